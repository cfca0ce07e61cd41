// A sensor stream a node hands straight to its estimator (livo-lio-graph's and livo-vio-feature's
// IMU and wheels): the estimator checks and keeps each sample, the node rejects what it refuses and
// keeps the stream's watermark, what its queued work waits for.
#pragma once

#include <cstdint>
#include <string>

#include "livo/node.hpp"

namespace livo {

class SensorFeed {
 public:
  /// Hands the sample stamped `utime` to the estimator: `add(why)` returns whether it took it (the
  /// estimator's checks: finite, later than the previous one). Refused, the sample is rejected on
  /// `channel` with the reason; taken, the watermark moves to utime and `why` keeps whatever else
  /// the estimator said (a warning, the reason of a reset). True when taken.
  template <class Add>
  bool take(Node& node, const std::string& channel, int64_t utime, Add&& add, std::string* why) {
    if (!add(why)) {
      node.reject(channel, *why);
      return false;
    }
    watermark_ = utime;
    return true;
  }

  /// The stamp of the last sample taken (INT64_MIN before the first).
  int64_t watermark() const { return watermark_; }

 private:
  int64_t watermark_ = INT64_MIN;
};

}  // namespace livo
