#include "livo/colour/pose_history.hpp"

#include <algorithm>

namespace livo::colour {

bool PoseHistory::add(int64_t utime, const Pose3& T) {
  if (!T.matrix().allFinite()) return false;
  auto it = std::lower_bound(poses_.begin(), poses_.end(), utime,
                             [](const std::pair<int64_t, Pose3>& e, int64_t t) { return e.first < t; });
  if (it != poses_.end() && it->first == utime)
    it->second = T;
  else
    poses_.insert(it, {utime, T});
  return true;
}

bool PoseHistory::at(int64_t utime, Pose3* T, int64_t max_gap_us) const {
  if (poses_.empty() || utime < poses_.front().first || utime > poses_.back().first) return false;
  auto it = std::lower_bound(poses_.begin(), poses_.end(), utime,
                             [](const std::pair<int64_t, Pose3>& e, int64_t t) { return e.first < t; });
  if (it->first == utime) {
    *T = it->second;
    return true;
  }
  const auto& b = *it;
  const auto& a = *(it - 1);
  if (b.first - a.first > max_gap_us) return false;
  *T = se3::interpolate(a.second, b.second, double(utime - a.first) / double(b.first - a.first));
  return true;
}

void PoseHistory::dropBefore(int64_t utime) {
  // keep one sample at or before `utime` so it can still be bracketed
  while (poses_.size() > 1 && poses_[1].first <= utime) poses_.pop_front();
}

}  // namespace livo::colour
