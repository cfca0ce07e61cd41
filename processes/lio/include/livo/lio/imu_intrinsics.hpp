// The IMU's scale-factor and axis errors as states of the filter: a reading is K u + bias with
// K = I + M, M a full 3x3 per sensor (the gyro's and the accelerometer's). Full, not only the
// lower-triangular sensing axes the simulator draws (livo/imu_axes.hpp): the filter's body is the
// one the LiDAR registers, turned from the IMU's by what the LiDAR mount's held rotation is off,
// and that rotation, the same for both sensors, is an antisymmetric part of each M. They are
// not part of FilterState (the hand-off's filter_state_t): no measurement sees them directly, only
// the propagation, so livo-lio keeps them beside the filter with their cross-covariance, carried
// by every propagation step and conditioned on every update (the LiDAR's, the wheels', an adopted
// VIO posterior) as the Kalman update of the augmented state does (conditionedOnUpdate).
// OpenVINS estimates the same (its "kalibr" IMU model: a triangular matrix and a rotation per
// triad); a rig states their 1-sigma (rig.imu.gyro_scale_std, gyro_misalignment_std,
// accel_scale_std, accel_misalignment_std) and the prior is the nominal sensor, zero error.
#pragma once

#include "livo/filter_state.hpp"

namespace livo::lio {

struct ImuIntrinsics {
  static constexpr int kDim = 18;
  static constexpr int kGyroScale = 0;   // 3: the diagonal of K_g - I
  static constexpr int kGyroCross = 3;   // 6: its off-diagonal (0,1) (0,2) (1,0) (1,2) (2,0) (2,1)
  static constexpr int kAccelScale = 9;  // the same for K_a
  static constexpr int kAccelCross = 12;
  using Vector = Eigen::Matrix<double, kDim, 1>;
  using Covariance = Eigen::Matrix<double, kDim, kDim>;

  Vector value = Vector::Zero();

  /// K = I + diag(scale) + the off-diagonal `cross` (kGyroCross's order).
  static Mat3 axes(const Vec3& scale, const Eigen::Matrix<double, 6, 1>& cross);
  /// ∂(K^-1 u)/∂[scale; cross] at the corrected reading w = K^-1 u (3x9).
  static Eigen::Matrix<double, 3, 9> readingJacobian(const Mat3& K, const Vec3& w);
  Mat3 gyroAxes() const { return axes(value.segment<3>(kGyroScale), value.segment<6>(kGyroCross)); }
  Mat3 accelAxes() const { return axes(value.segment<3>(kAccelScale), value.segment<6>(kAccelCross)); }
  /// The body rate K_g^-1 (gyro - b_g) and specific force K_a^-1 (accel - b_a) a reading stands for.
  Vec3 angularVelocity(const Vec3& gyro, const Vec3& gyro_bias) const;
  Vec3 specificForce(const Vec3& accel, const Vec3& accel_bias) const;
};

/// The prior covariance: the rig's 1-sigmas on the diagonal (0: that part is not modelled); the
/// off-diagonal entries take the misalignment's.
ImuIntrinsics::Covariance intrinsicsPrior(double gyro_scale_std, double gyro_misalignment_std, double accel_scale_std,
                                          double accel_misalignment_std);

}  // namespace livo::lio
