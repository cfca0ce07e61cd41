// The ESIKF state (paper 1 eq. 4) with the sensors' calibration in it, as R3LIVE and FAST-LIO2
// estimate theirs: M = SO(3) x R^15 (the navigation state) x (SO(3) x R^4)^2 (the LiDAR's and the
// camera's extrinsic and time shift), with the ⊞ / ⊟ operators of eq. (1)-(2).
#pragma once

#include "livo/so3.hpp"

namespace livo {

/// A sensor's mounting and clock as the filter believes them: the extrinsic T_I_S (p_I = T_I_S p_S)
/// and the time shift dt: a sample the rig puts at IMU time t (its stamp plus the rig's stated
/// time_offset_s) was taken at IMU time t + dt. The rig's values are the prior (dt = 0).
struct SensorCalibration {
  Mat3 rot = Mat3::Identity();  // R_I_S
  Vec3 pos = Vec3::Zero();      // t_I_S
  double dt = 0.0;              // s

  Pose3 pose() const { return se3::fromRotationTranslation(rot, pos); }
  static SensorCalibration fromPose(const Pose3& T_I_S, double dt = 0.0) {
    return SensorCalibration{T_I_S.linear(), T_I_S.translation(), dt};
  }
};

struct FilterState {
  static constexpr int kNavDim = 18;         // rotation, position, velocity, biases, gravity
  static constexpr int kCalibrationDim = 7;  // a sensor's extrinsic rotation, translation, time shift
  static constexpr int kDim = kNavDim + 2 * kCalibrationDim;
  // Offsets of each block in the error state.
  static constexpr int kRot = 0;
  static constexpr int kPos = 3;
  static constexpr int kVel = 6;
  static constexpr int kGyroBias = 9;
  static constexpr int kAccelBias = 12;
  static constexpr int kGravity = 15;
  static constexpr int kLidar = 18;   // LiDAR calibration: rotation (right perturbation of R_I_L) ...
  static constexpr int kCamera = 25;  // camera calibration: ... translation, time shift
  // offsets inside a calibration block
  static constexpr int kCalRot = 0;
  static constexpr int kCalPos = 3;
  static constexpr int kCalDt = 6;

  Mat3 rot = Mat3::Identity();  // W_R_I
  Vec3 pos = Vec3::Zero();      // W_p_I
  Vec3 vel = Vec3::Zero();      // W_v_I
  Vec3 gyro_bias = Vec3::Zero();
  Vec3 accel_bias = Vec3::Zero();
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);
  SensorCalibration lidar;   // T_I_L and its time shift
  SensorCalibration camera;  // T_I_C and its time shift

  using Vector = Eigen::Matrix<double, kDim, 1>;
  using Covariance = Eigen::Matrix<double, kDim, kDim>;

  /// x ⊞ d: R Exp(d_rot) for the three rotations, the rest added.
  FilterState boxplus(const Vector& d) const;
  /// x ⊟ y: Log(y.R^T x.R) for the three rotations, the rest subtracted.
  Vector boxminus(const FilterState& y) const;

  /// H = ∂((x ⊞ d) ⊟ y) / ∂d at d = 0 (paper eq. 12): JrInv(x ⊟ y) on the rotation blocks,
  /// identity elsewhere.
  static Covariance boxminusJacobian(const FilterState& x, const FilterState& y);

  /// The error-state offsets of the three rotation blocks.
  static constexpr int kRotationBlocks[3] = {kRot, kLidar + kCalRot, kCamera + kCalRot};

  Pose3 pose() const { return se3::fromRotationTranslation(rot, pos); }
  const SensorCalibration& calibration(int block) const { return block == kLidar ? lidar : camera; }
};

using StateVector = FilterState::Vector;
using StateCovariance = FilterState::Covariance;
// the navigation block alone (the IMU initialisation, propagation Jacobians)
using Vec18 = Eigen::Matrix<double, FilterState::kNavDim, 1>;
using Mat18 = Eigen::Matrix<double, FilterState::kNavDim, FilterState::kNavDim>;

/// Whether P is a covariance the filter can use: finite, symmetric to rounding, and positive
/// definite on the states it estimates (those with a positive variance; a zero variance, with its
/// row and column zero, is a state held fixed, such as a calibration the rig states as exact).
bool isUsableCovariance(const StateCovariance& P);

/// The prior covariance of a sensor's calibration block: rotation, translation and time shift
/// 1-sigmas (0: held fixed at the rig's value).
struct CalibrationStd {
  double rotation = 0.0;     // rad per axis
  double translation = 0.0;  // m per axis
  double time = 0.0;         // s
  bool any() const { return rotation > 0.0 || translation > 0.0 || time > 0.0; }
};
/// Writes the block's diagonal prior into P (the block's rows and columns are cleared first).
void setCalibrationPrior(int block, const CalibrationStd& sigma, StateCovariance* P);

}  // namespace livo
