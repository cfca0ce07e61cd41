// IMU forward propagation of the ESIKF (paper eqs. 3-8): the state x_{i+1} = x_i ⊞ (Δt f(x_i, u_i, 0))
// on SO(3) x R^15 with gravity in the state, and the covariance P_{i+1} = F_x P F_x^T + F_w Q F_w^T
// for the right-perturbation error state [rot pos vel bg ba g] (FilterState's order). The sensors'
// calibration is constant: propagation moves only its correlation with the navigation state.
// The input u_i of a step is the mean of the two IMU samples that bound it.
#pragma once

#include <cstdint>
#include <vector>

#include "livo/filter_state.hpp"
#include "livo/imu_preintegration.hpp"
#include "livo/lio/imu_intrinsics.hpp"
#include "livo/lio/keyframe_clone.hpp"
#include "livo/sensor_samples.hpp"

namespace livo::lio {

using Mat18x12 = Eigen::Matrix<double, 18, 12>;
using Mat12 = Eigen::Matrix<double, 12, 12>;
using IntrinsicsJacobian = Eigen::Matrix<double, FilterState::kNavDim, ImuIntrinsics::kDim>;

/// Continuous-time noise of the IMU (the rig's imu section): the densities and the gyro's scale and
/// misalignment budget as the preintegration has them (livo/imu_preintegration.hpp; here the
/// systematic_error_window_s is the LiDAR sweep period, the attitude being corrected once a sweep),
/// plus the accelerometer's axis errors (rig.imu.accel_scale_std, accel_misalignment_std), used only
/// where the axes are modelled as states (ImuIntrinsics); the noise budget is the gyro's alone.
struct ImuNoise : ImuPreintegrationNoise {
  double accel_scale_std = 0.0;
  double accel_misalignment_std = 0.0;
};

/// The prior of the IMU's sensing-axis errors from the rig's stated 1-sigmas.
inline ImuIntrinsics::Covariance intrinsicsPrior(const ImuNoise& n) {
  return intrinsicsPrior(n.gyro_scale_std, n.gyro_misalignment_std, n.accel_scale_std, n.accel_misalignment_std);
}

/// Eq. (5): x ⊞ (dt f(x, u, 0)) with f of eq. (4), the readings taken through the IMU's sensing
/// axes (`intrinsics`; the default is the nominal sensor).
FilterState propagateState(const FilterState& x, const Vec3& gyro, const Vec3& accel, double dt,
                           const ImuIntrinsics& intrinsics = {});

/// F_x = ∂δx_{i+1}/∂δx_i and F_w = ∂δx_{i+1}/∂w_i (eq. 8), w = [n_w n_a n_bw n_ba]; with `Fm`,
/// also ∂δx_{i+1}/∂(intrinsics) (the navigation rows; the intrinsics are constant).
void propagationJacobians(const FilterState& x, const Vec3& gyro, const Vec3& accel, double dt, Mat18* Fx, Mat18x12* Fw,
                          const ImuIntrinsics& intrinsics = {}, IntrinsicsJacobian* Fm = nullptr);

/// Covariance of the discrete noise w_i over a step of dt: density^2 / dt per axis; the gyro's part
/// grows with the bias-corrected rate `omega` when the scale or misalignment error is modelled.
Mat12 discreteNoiseCovariance(const ImuNoise& noise, double dt, const Vec3& omega = Vec3::Zero());

/// The IMU-rate trajectory over one step: state at `utime` and the constant input until the next.
struct ImuSegment {
  int64_t utime = 0;
  Mat3 rot = Mat3::Identity();
  Vec3 pos = Vec3::Zero();
  Vec3 vel = Vec3::Zero();
  Vec3 omega = Vec3::Zero();      // bias-corrected angular rate, frame I
  Vec3 acc_world = Vec3::Zero();  // R (a - b_a) + g, frame W
};

/// Holds the filter's state and covariance at time utime() and propagates them through IMU samples.
class ImuPropagator {
 public:
  explicit ImuPropagator(ImuNoise noise = {}) : noise_(noise) {}

  /// Sets the state at `last.utime`; `last` is the IMU sample at that instant (first input half).
  void reset(const FilterState& x, const StateCovariance& P, const ImuSample& last);
  /// Replaces state and covariance at the current time (after an update).
  void setState(const FilterState& x, const StateCovariance& P);
  /// The state's cross-covariance with a cloned pose (KeyframeClone): every step carries it with
  /// the state's transition (the clone is constant). reset() zeroes it; setState() leaves it.
  void setCloneCross(const CloneCrossCovariance& C) { clone_cross_ = C; }
  const CloneCrossCovariance& cloneCross() const { return clone_cross_; }
  /// Clones the current pose: its cross-covariances with the state and the intrinsics.
  void clonePose();

  /// Models the IMU's sensing axes with this prior (a zero 1-sigma holds that part): the
  /// readings are taken through them and their cross-covariance with the state is carried
  /// through every step and update. `estimate`: the updates correct them (the Kalman update of
  /// the augmented state); otherwise they are considered (Schmidt): their value and covariance
  /// stay, only their correlation with the state is tracked, so the state's covariance holds what
  /// their error does to it. reset() keeps them (they belong to the sensor) and zeroes their
  /// cross-covariance.
  void setIntrinsics(const ImuIntrinsics& k, const ImuIntrinsics::Covariance& P, bool estimate);
  /// Whether the axes are modelled as states (estimated or considered).
  bool modelsIntrinsics() const { return model_intrinsics_; }
  const ImuIntrinsics& intrinsics() const { return intrinsics_; }
  const ImuIntrinsics::Covariance& intrinsicsCovariance() const { return intrinsics_cov_; }
  /// The bias- and axis-corrected body rate of a gyro reading under the state x.
  Vec3 angularVelocity(const Vec3& gyro, const FilterState& x) const {
    return model_intrinsics_ ? intrinsics_.angularVelocity(gyro, x.gyro_bias) : Vec3(gyro - x.gyro_bias);
  }

  /// Adopts the result of an update of the current state (the LiDAR's, the wheels', a VIO
  /// posterior) and conditions what is kept beside the filter on it: the clone's and the
  /// intrinsics' cross-covariances, the intrinsics themselves (conditionedOnUpdate).
  void applyUpdate(const FilterState& x, const StateCovariance& P);
  /// A change of the world frame: the state becomes x, P <- T P T^T, and the cross-covariances
  /// move with it (the clone's errors by its own frame change Tc; the intrinsics are the sensor's).
  void changeFrame(const FilterState& x, const StateCovariance& T, const Mat6& Tc);

  /// Propagates through one sample later than utime() (eq. 5-6 with u = mean of the bounding
  /// samples). Samples at or before utime() are ignored (returns false).
  bool addSample(const ImuSample& s);
  /// Propagates to `utime` (>= utime()) inside the interval ending at `next`, interpolating the
  /// sample at `utime` between the last one and `next`. If next.utime <= utime the last
  /// sample is held.
  void propagateTo(int64_t utime, const ImuSample& next);

  const FilterState& state() const { return x_; }
  const StateCovariance& covariance() const { return P_; }
  int64_t utime() const { return last_.utime; }
  const ImuSample& lastSample() const { return last_; }
  const ImuNoise& noise() const { return noise_; }

  /// Steps taken since clearSegments(), in time order (for undistortion), and the final state's
  /// time as the end of the last one.
  const std::vector<ImuSegment>& segments() const { return segments_; }
  void clearSegments() { segments_.clear(); }
  /// Forgets segments that ended before `utime` (bounded memory while no sweep consumes them).
  void dropSegmentsBefore(int64_t utime);
  /// Moves the recorded segments rigidly by T (world frame: p -> R p + t), so that the trajectory
  /// stays continuous when an external update moves the current state by T.
  void transformSegments(const Pose3& T);

 private:
  void step(const ImuSample& next);

  ImuNoise noise_;
  FilterState x_;
  StateCovariance P_ = StateCovariance::Identity();
  CloneCrossCovariance clone_cross_ = CloneCrossCovariance::Zero();
  bool model_intrinsics_ = false;   // modelled (considered or estimated)
  bool update_intrinsics_ = false;  // estimated
  ImuIntrinsics intrinsics_;
  ImuIntrinsics::Covariance intrinsics_cov_ = ImuIntrinsics::Covariance::Zero();
  Eigen::Matrix<double, FilterState::kDim, ImuIntrinsics::kDim> intrinsics_cross_ =
      Eigen::Matrix<double, FilterState::kDim, ImuIntrinsics::kDim>::Zero();  // Cov(δx, δk)
  Eigen::Matrix<double, ImuIntrinsics::kDim, 6> intrinsics_clone_cross_ =
      Eigen::Matrix<double, ImuIntrinsics::kDim, 6>::Zero();  // Cov(δk, δclone)
  ImuSample last_;
  std::vector<ImuSegment> segments_;
};

}  // namespace livo::lio
