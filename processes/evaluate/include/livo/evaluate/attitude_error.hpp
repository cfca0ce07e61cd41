// Roll, pitch and tilt error of an estimate against ground truth: how well it knows where gravity
// points in the body. All three are functions of the up direction in the body frame, R^T e_z (the
// bottom row of the world-from-body rotation R), so a rotation of the estimate's world about z (what
// a 4-DoF alignment applies) changes none of them. World z must be up (against gravity) in both.
#pragma once

#include <vector>

#include "livo/evaluate/error_statistics.hpp"
#include "livo/so3.hpp"

namespace livo::evaluate {

/// Roll and pitch of a world-from-body rotation in its ZYX decomposition R = Rz(yaw) Ry(pitch)
/// Rx(roll), radians: roll = atan2(R21, R22) in (-pi, pi], pitch = atan2(-R20, hypot(R21, R22)) in
/// [-pi/2, pi/2].
struct RollPitch {
  double roll = 0.0;
  double pitch = 0.0;
};
RollPitch rollPitchOf(const Mat3& world_from_body);

struct AttitudeError {
  std::vector<double> roll_deg;   // per pair: roll(est) - roll(gt), wrapped to (-180, 180]
  std::vector<double> pitch_deg;  // per pair: pitch(est) - pitch(gt)
  std::vector<double> tilt_deg;   // per pair: angle between R_est^T e_z and R_gt^T e_z, >= 0
  ErrorStatistics roll, pitch, tilt;
};

/// `gt` and `est` are the associated pose lists (same length), in worlds with z up.
AttitudeError attitudeError(const std::vector<Pose3>& gt, const std::vector<Pose3>& est);

}  // namespace livo::evaluate
