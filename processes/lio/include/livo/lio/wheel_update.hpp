// Wheel-encoder velocity update for ground vehicles (the APGC-LVIW paper's wheel fusion in filter
// form): the wheel frame B moves forward at the mean wheel speed with no lateral or vertical
// velocity. With p_I = T_I_B p_B, the predicted velocity of B in B is
//   v_B = R_IB^T (R^T v + (ω_m - b_g) × t_IB),
// a 3-vector measurement of rotation, velocity and gyro bias, fused by a (chi-square gated)
// EKF update.
#pragma once

#include <cstdint>

#include "livo/filter_state.hpp"
#include "livo/sensor_samples.hpp"

namespace livo::lio {

using Mat3xState = Eigen::Matrix<double, 3, FilterState::kDim>;

struct WheelOptions {
  bool enabled = false;
  Pose3 T_I_B = Pose3::Identity();  // p_I = T_I_B p_B; B: x forward, z up
  double track_width = 0.5;         // m (rig; kept for a yaw-rate measurement)
  double speed_noise_std = 0.02;    // m/s, per wheel (rig)
  double lateral_noise_std = 0.05;  // m/s, the non-holonomic constraints
  double vertical_noise_std = 0.1;  // m/s: a car's suspension moves the body-fixed B up and down
  double max_sample_gap_s = 0.1;    // interpolate the speed only between samples this close
  double gate_chi2 = 16.27;         // 3 dof, 0.1 %: larger innovations (slip) are rejected
};

/// Predicted velocity of B in B.
Vec3 wheelFrameVelocity(const FilterState& x, const Vec3& gyro_measured, const Pose3& T_I_B);
/// Its Jacobian with respect to the error state (rotation, velocity and gyro-bias blocks).
Mat3xState wheelVelocityJacobian(const FilterState& x, const Vec3& gyro_measured, const Pose3& T_I_B);

struct WheelUpdateResult {
  bool applied = false;
  double chi2 = 0.0;               // normalised innovation squared
  Vec3 innovation = Vec3::Zero();  // predicted minus measured velocity of B in B, m/s
};

/// Updates (x, P) with the forward speed (mean of the wheels) and zero lateral/vertical velocity.
/// extra_forward_variance (m²/s²) adds to the forward speed's variance (e.g. the uncertainty of
/// the wheel scales, wheel_scale.hpp).
WheelUpdateResult wheelVelocityUpdate(FilterState* x, StateCovariance* P, const Vec3& gyro_measured,
                                      double forward_speed, const WheelOptions& options,
                                      double extra_forward_variance = 0.0);

}  // namespace livo::lio
