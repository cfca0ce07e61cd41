#include "livo/keyframe_selector.hpp"

#include <cmath>

namespace livo {

bool KeyframeSelector::check(const Pose3& pose) {
  if (has_last_) {
    const double dist = (pose.translation() - last_.translation()).norm();
    const double angle = so3::Log(Mat3(last_.linear().transpose() * pose.linear())).norm();
    if (dist < opts_.min_distance && angle < opts_.min_angle_deg * M_PI / 180.0) return false;
  }
  setReference(pose);
  return true;
}

}  // namespace livo
