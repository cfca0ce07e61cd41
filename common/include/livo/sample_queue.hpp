// Samples a node holds until the streams they wait for have passed their time, for the nodes that
// take their inputs in arrival order (livo-lio-graph's sweeps, livo-vio-feature's images and scans).
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <utility>

namespace livo {

/// Stamped samples held oldest first. They must come in time order: a sample not later than the
/// newest one held is refused, not reordered (TimeBuffer, livo/time.hpp, reorders instead). The
/// stamp of the last sample taken is the stream's watermark: what a sample of another stream
/// waits for.
template <class T>
class SampleQueue {
 public:
  /// Whether a sample stamped `utime` would be taken: it is later than the newest sample held.
  bool takes(int64_t utime) const { return samples_.empty() || utime > last_taken_; }

  /// Holds `sample`, stamped `utime`; false (nothing held) if takes(utime) does not hold.
  bool pushLater(int64_t utime, T sample) {
    if (!takes(utime)) return false;
    samples_.push_back(std::move(sample));
    last_taken_ = utime;
    return true;
  }

  /// Hands the oldest sample to `fn` and then drops it, as long as `ready(oldest)` holds.
  template <class Ready, class Fn>
  void popWhile(Ready&& ready, Fn&& fn) {
    while (!samples_.empty() && ready(samples_.front())) {
      fn(samples_.front());
      samples_.pop_front();
    }
  }

  /// Drops the oldest sample (when too many wait); the queue must not be empty.
  void popFront() { samples_.pop_front(); }

  /// The stamp of the last sample taken, held or not (INT64_MIN before the first): the stream's
  /// watermark. While samples are held it is the newest one's.
  int64_t watermark() const { return last_taken_; }
  bool empty() const { return samples_.empty(); }
  size_t size() const { return samples_.size(); }
  const T& front() const { return samples_.front(); }
  const T& back() const { return samples_.back(); }
  /// The samples held, oldest first.
  const std::deque<T>& samples() const { return samples_; }

 private:
  std::deque<T> samples_;
  int64_t last_taken_ = INT64_MIN;
};

}  // namespace livo
