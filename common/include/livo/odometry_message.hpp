// The odometry output (odometry_t) as livo-lio, livo-lio-graph and livo-vio-feature publish it:
// each fills an OdometryOutput from its own result, and the message is built here once.
#pragma once

#include <cstdint>
#include <string>

#include "livo/odometry_t.hpp"
#include "livo/output_messages.hpp"
#include "livo/so3.hpp"

namespace livo {

/// One odometry estimate: the pose of the body "I" in `parent_frame` at `utime`, its uncertainty
/// and what the update that made it used (lcmtypes/odometry_t.lcm).
struct OdometryOutput {
  int64_t utime = 0;
  std::string parent_frame = "W";  // "W" the odometry frame of the LIOs, "V" the visual subsystem's
  Pose3 pose = Pose3::Identity();
  Vec3 velocity = Vec3::Zero();
  Vec3 angular_velocity = Vec3::Zero();  // bias-corrected, frame I
  Mat6 pose_covariance = Mat6::Zero();   // [rotation (right perturbation); position]
  Mat3 velocity_covariance = Mat3::Zero();
  int32_t num_residuals = 0;  // 0: none (a predicted sweep, the first of an epoch)
  bool degenerate = false;    // some direction was left to the prediction
  double min_information_eigenvalue = 0.0;
};

/// The message (child frame "I") in `frame` (epoch, correction_id).
odometry_t odometryMessage(const OdometryOutput& o, const OutputFrame& frame);

}  // namespace livo
