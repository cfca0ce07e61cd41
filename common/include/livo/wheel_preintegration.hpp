// Preintegration of a differential-drive wheel encoder (the APGC-LVIW paper's wheel encoder
// factor, its eqs. 11-17, after Ground-Fusion): the rotation and translation of the wheel frame
// O between two states, in O at the first, with their 6x6 covariance.
//
// O is the rig's base frame B (WheelRig::T_I_B, the pose of B in the IMU frame; turned by the
// mounting correction below where it is estimated): x forward, z up, origin between the wheels.
// From the wheel speeds the forward speed is v = (v_l + v_r) / 2 and the yaw rate
// w = (v_r - v_l) / track_width; between two readings (midpoint integration, both averaged over the
// interval's ends)
//   ΔR_{k+1} = ΔR_k Exp(z w dt),   Δp_{k+1} = Δp_k + ΔR_k Exp(½ z w dt) [v dt, 0, 0]^T,
// exact on a straight line; on an arc each chord is v dt instead of v dt sinc(½ w dt) (relative
// error (w dt)² / 24).
//
// Noise. The encoder measures only the forward speed and the yaw rate; the other four directions
// (lateral and vertical velocity, roll and pitch rate) are the planar, no-slip motion assumption
// and get a stated sigma, so the covariance is not singular. Every sigma is that of one reading at
// the encoder's rate (white noise: an interval of dt seconds has the variance sigma² / (rate_hz dt),
// so the variance of a distance grows with its duration whatever the readings' spacing). Errors
// follow the IMU preintegration: ΔR̃ = ΔR Exp(δθ), Δp̃ = Δp + δp, covariance() = Cov([δθ, δp]).
//
// Wheel scales. Real tyres are not the nominal radius (pressure, load, wear: about 1 %), which a
// planar-motion prior cannot absorb. With true speeds s_l v_l and s_r v_r, the preintegrated motion
// depends on s = [s_l, s_r] (1 at the nominal radius); like the IMU biases it is corrected to first
// order, ΔR(s) = ΔR Exp(J_R (s - 1)), Δp(s) = Δp + J_p (s - 1), with J_R, J_p integrated alongside.
//
// Mounting. The rig's T_I_B is a calibration, good to a few tenths of a degree. The wheels drive
// along the true O's x, so a yaw error of R_IB puts their forward speed sideways in the body (a
// lateral velocity the IMU and the LiDAR contradict) and a pitch error puts it vertically (a height
// drift of d sin(pitch) over a distance d, 0.9 m per 100 m at 0.5 deg). The residual therefore
// takes O as B turned by Exp(δ), R_IO = R_IB Exp(δ) (δ = 0: the rig's nominal; the lever arm t_IB
// stays), with δ a parameter block the graphs estimate under the rig's stated uncertainty
// (WheelRig::calibration_std). All three axes, not only yaw and pitch: the prior holds the roll,
// which the wheels hardly see (a rotation about the direction of motion; only in turns does it
// tilt the yaw-rate axis, against the roll/pitch-rate sigma), so a 3-vector costs one direction
// that the prior alone decides, and in exchange the block is the plain rotation vector of the
// mounting error, with the same isotropic prior as the LiDAR's and the camera's extrinsics, and no
// choice of which two axes a vehicle's "forward" makes observable.
#pragma once

#include <string>

#include "livo/imu_preintegration.hpp"  // quaternionExp/Log for the templated residual, upperSqrtInformation
#include "livo/sensor_rig.hpp"
#include "livo/so3.hpp"

namespace livo {

/// A mounting correction δ (rad) for a log line: "wheel mounting off the rig's by roll R, pitch P,
/// yaw Y deg" (δ's components about the wheel frame's x, y, z: roll, pitch and yaw at these angles).
std::string wheelMountingText(const Vec3& mounting);

/// The wheel factor in a graph's options line (--check-config): "wheel preintegration", then
/// " (tyre scales estimated, prior sigma S)" where scale_std > 0 and " through the estimated
/// mounting rotation (prior sigma R deg)" where the rig states its uncertainty.
std::string wheelFactorText(const WheelRig& rig, double scale_std);

struct WheelPreintegrationNoise {
  double speed_std = 0.02;  // m/s per wheel (WheelRig::speed_noise_std)
  // The planar-motion assumption; defaults for a car on a road, as the LIO's wheel update:
  double lateral_speed_std = 0.05;   // m/s, sideways slip
  double vertical_speed_std = 0.1;   // m/s, the suspension moving the body-fixed frame
  double roll_pitch_rate_std = 0.1;  // rad/s, body roll and pitch on bumps and in turns

  /// speed_std from the rig, the planar-motion sigmas at their defaults.
  static WheelPreintegrationNoise fromRig(const WheelRig& rig);
};

class WheelPreintegration {
 public:
  /// Uses the rig's rate_hz (noise), track_width and T_I_B (residual).
  WheelPreintegration(const WheelRig& rig, const WheelPreintegrationNoise& noise);

  /// Adds the interval of dt seconds between two readings (left and right wheel speeds in m/s at
  /// its start, 0, and end, 1). dt == 0 adds nothing; a negative or non-finite dt throws
  /// std::invalid_argument.
  void integrate(double v_left0, double v_right0, double v_left1, double v_right1, double dt);

  double duration() const { return duration_; }
  /// Rotation of O at the end in O at the start.
  const Mat3& deltaR() const { return delta_R_; }
  /// Position of O at the end in O at the start.
  const Vec3& deltaP() const { return delta_p_; }
  /// Cov([δθ, δp]).
  const Mat6& covariance() const { return covariance_; }
  /// Upper-triangular U with U^T U = covariance()^-1 (upperSqrtInformation, imu_preintegration.hpp).
  Mat6 sqrtInformation() const;
  /// d(δθ)/ds and d(Δp)/ds at s = [1, 1] (wheel scales, above).
  const Eigen::Matrix<double, 3, 2>& rotationScaleJacobian() const { return dR_ds_; }
  const Eigen::Matrix<double, 3, 2>& positionScaleJacobian() const { return dp_ds_; }

  /// [r_R, r_p] for the IMU poses W_T_I at i and j, with T_W_O = T_W_I T_I_B:
  ///   r_R = Log(ΔR^T R_Oi^T R_Oj),  r_p = R_Oi^T (p_Oj - p_Oi) - Δp.
  Vec6 residual(const Mat3& R_i, const Vec3& p_i, const Mat3& R_j, const Vec3& p_j) const;

  /// The same on raw parameter blocks for Ceres AutoDiff: unit quaternions W_R_I in Eigen's order
  /// [x, y, z, w], positions W_p_I; r has 6 entries.
  template <class T>
  void residual(const T* q_i, const T* p_i, const T* q_j, const T* p_j, T* r) const;
  /// The same with the wheel scales s = [s_l, s_r] (the preintegration corrected to first order).
  template <class T>
  void residual(const T* q_i, const T* p_i, const T* q_j, const T* p_j, const T* scale, T* r) const;
  /// The same with the wheel frame turned by the mounting correction δ (3 entries, a rotation
  /// vector): R_IO = R_IB Exp(δ) (above); δ = 0 gives the overload without it exactly.
  template <class T>
  void residual(const T* q_i, const T* p_i, const T* q_j, const T* p_j, const T* scale, const T* mounting, T* r) const;

 private:
  double track_width_;
  double rate_hz_;
  Quat q_IB_;
  Vec3 t_IB_;
  WheelPreintegrationNoise noise_;
  double duration_ = 0.0;
  Quat delta_q_ = Quat::Identity();  // ΔR kept as a unit quaternion; delta_R_ is its matrix
  Mat3 delta_R_ = Mat3::Identity();
  Vec3 delta_p_ = Vec3::Zero();
  Mat6 covariance_ = Mat6::Zero();
  Eigen::Matrix<double, 3, 2> dR_ds_ = Eigen::Matrix<double, 3, 2>::Zero();
  Eigen::Matrix<double, 3, 2> dp_ds_ = Eigen::Matrix<double, 3, 2>::Zero();

  /// The residual with O's orientation in the body q_IO (the rig's q_IB, or it turned by δ).
  template <class T>
  void residualWithWheelFrame(const Eigen::Quaternion<T>& q_IO, const T* q_i, const T* p_i, const T* q_j, const T* p_j,
                              const T* scale, T* r) const;
};

template <class T>
void WheelPreintegration::residual(const T* q_i, const T* p_i, const T* q_j, const T* p_j, T* r) const {
  const T unit[2] = {T(1.0), T(1.0)};
  residual(q_i, p_i, q_j, p_j, unit, r);
}

template <class T>
void WheelPreintegration::residual(const T* q_i, const T* p_i, const T* q_j, const T* p_j, const T* scale, T* r) const {
  residualWithWheelFrame(Eigen::Quaternion<T>(q_IB_.cast<T>()), q_i, p_i, q_j, p_j, scale, r);
}

template <class T>
void WheelPreintegration::residual(const T* q_i, const T* p_i, const T* q_j, const T* p_j, const T* scale,
                                   const T* mounting, T* r) const {
  const Eigen::Matrix<T, 3, 1> delta(mounting[0], mounting[1], mounting[2]);
  residualWithWheelFrame(Eigen::Quaternion<T>(q_IB_.cast<T>() * quaternionExp<T>(delta)), q_i, p_i, q_j, p_j, scale, r);
}

template <class T>
void WheelPreintegration::residualWithWheelFrame(const Eigen::Quaternion<T>& q_IO, const T* q_i, const T* p_i,
                                                 const T* q_j, const T* p_j, const T* scale, T* r) const {
  using Vec3T = Eigen::Matrix<T, 3, 1>;
  using QuatT = Eigen::Quaternion<T>;
  const Eigen::Map<const QuatT> Q_i(q_i), Q_j(q_j);
  const Eigen::Map<const Vec3T> P_i(p_i), P_j(p_j);
  const Vec3T t_IB = t_IB_.cast<T>();
  const QuatT Q_Oi = Q_i * q_IO, Q_Oj = Q_j * q_IO;
  const Vec3T P_Oi = P_i + Q_i * t_IB, P_Oj = P_j + Q_j * t_IB;
  const QuatT Q_Oi_inv = Q_Oi.conjugate();
  const Eigen::Matrix<T, 2, 1> ds(scale[0] - T(1.0), scale[1] - T(1.0));
  const QuatT dq = delta_q_.cast<T>() * quaternionExp<T>(Vec3T(dR_ds_.cast<T>() * ds));
  Eigen::Map<Eigen::Matrix<T, 6, 1>> res(r);
  res.template head<3>() = quaternionLog<T>(dq.conjugate() * (Q_Oi_inv * Q_Oj));
  res.template tail<3>() = Q_Oi_inv * Vec3T(P_Oj - P_Oi) - (delta_p_.cast<T>() + dp_ds_.cast<T>() * ds);
}

}  // namespace livo
