// Body poses in time order with interpolation (slerp + linear), from ODOMETRY and the poses that
// REGISTERED_SCAN carries; the camera pose at an image's time comes from here.
#pragma once

#include <cstdint>
#include <deque>

#include "livo/so3.hpp"

namespace livo::colour {

class PoseHistory {
 public:
  /// Inserts in time order (an equal stamp replaces). Non-finite poses are refused (false).
  bool add(int64_t utime, const Pose3& T_W_I);
  /// Pose at `utime` if it lies within [front, back] and the bracketing samples are at most
  /// `max_gap_us` apart.
  bool at(int64_t utime, Pose3* T_W_I, int64_t max_gap_us = 500000) const;
  void dropBefore(int64_t utime);
  bool empty() const { return poses_.empty(); }
  int64_t newest() const { return poses_.empty() ? INT64_MIN : poses_.back().first; }
  size_t size() const { return poses_.size(); }

 private:
  std::deque<std::pair<int64_t, Pose3>> poses_;
};

}  // namespace livo::colour
