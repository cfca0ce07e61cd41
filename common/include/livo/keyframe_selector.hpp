// Keyframe selection by travelled distance and rotation since the last keyframe.
#pragma once

#include "livo/so3.hpp"

namespace livo {

struct KeyframeOptions {
  double min_distance = 1.0;    // m
  double min_angle_deg = 10.0;  // degrees
  double cloud_voxel = 0.2;     // m, downsampling of the keyframe's body-frame cloud
};

class KeyframeSelector {
 public:
  explicit KeyframeSelector(KeyframeOptions options = {}) : opts_(options) {}
  /// True (and the pose becomes the reference) for the first pose and whenever the pose moved
  /// min_distance or turned min_angle_deg from the last keyframe.
  bool check(const Pose3& pose);
  /// The next pose becomes a keyframe; or the reference is moved (loop correction).
  void reset() { has_last_ = false; }
  void setReference(const Pose3& pose) {
    last_ = pose;
    has_last_ = true;
  }
  const KeyframeOptions& options() const { return opts_; }

 private:
  KeyframeOptions opts_;
  Pose3 last_ = Pose3::Identity();
  bool has_last_ = false;
};

}  // namespace livo
