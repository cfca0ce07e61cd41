// The odometry's relative pose between consecutive keyframes and its covariance, from the filter
// itself (stochastic cloning, Roumeliotis & Burdick 2002). The pose at the last keyframe is kept
// with its covariance, and the cross-covariance of the running state with it is carried by every
// propagation step (with the state's transition: the clone is constant) and every update (with
// I - K H). At the next keyframe the relative pose's covariance follows to first order,
// correlations included: differencing the two absolute covariances cannot give it (with a map
// both barely grow, while the increment between them is as uncertain as the registrations that
// made it). livo-loop weights its odometry edges with it; tests/loop/keyframe_nees.py checks it
// against the simulator's truth.
#pragma once

#include "livo/filter_state.hpp"

namespace livo::lio {

/// Cov(δx, δpose_clone): the filter's error state against the clone's [rotation; position].
using CloneCrossCovariance = Eigen::Matrix<double, FilterState::kDim, 6>;

struct KeyframeClone {
  bool valid = false;
  int64_t keyframe_id = -1;
  Pose3 pose = Pose3::Identity();  // W_T_I at that keyframe
  Mat6 covariance = Mat6::Zero();  // its [rotation (right); position (world)] error covariance
};

/// Covariance of the right perturbation xi = [rotation; translation in b] of T_a^-1 T_b (true
/// relative pose = (R Exp(phi), t + R tau) to first order, livo-loop's convention for its edges),
/// from the filter's errors of the two poses ([rotation, right; position, world] each): their
/// covariances and Cov(δb, δa).
Mat6 relativePoseCovariance(const Pose3& T_a, const Pose3& T_b, const Mat6& P_aa, const Mat6& P_bb, const Mat6& P_ba);

/// What the filter's covariance cannot contain: calibration it holds at the rig's values (the
/// parts of rig.lidar.calibration_std that livo-lio does not estimate; the gyro's scale and axis
/// misalignment, rig.imu.gyro_scale_std / gyro_misalignment_std, which are never states). Their
/// errors are the same through a whole run, so no update reveals them and the filter's increments
/// are too confident by what they cause: on campus_loop_hard (LiDAR-IMU 0.3 deg / 1 cm, gyro 1 % /
/// 7 mrad) the increments' NEES is 134 against 6 (README, "The increment between keyframes").
struct HeldCalibration {
  Pose3 T_I_L = Pose3::Identity();     // the LiDAR-IMU extrinsic in use
  double lidar_rotation_std = 0.0;     // rad per axis (0: estimated, or not stated)
  double lidar_translation_std = 0.0;  // m per axis (0: estimated, or not stated)
  double gyro_scale_std = 0.0;         // relative, per axis
  double gyro_misalignment_std = 0.0;  // rad, per off-diagonal element
  bool any() const {
    return lidar_rotation_std > 0.0 || lidar_translation_std > 0.0 || gyro_scale_std > 0.0 ||
           gyro_misalignment_std > 0.0;
  }
};

/// The covariance the held calibration adds to the increment T_rel = T_prev^-1 T_this (Schmidt's
/// consider covariance), in relativePoseCovariance's convention:
/// - LiDAR-IMU extrinsic X off by the right perturbation c = [rotation; translation]: the LiDAR's
///   motion is registered, so the body increment reported is X L X^-1 where the truth is
///   X Exp(c) L Exp(-c) X^-1. The truth is then T_rel Exp(xi) with xi = (Ad(T_rel^-1) - I) Ad(X) c
///   to first order: a rotation error of the mount turns each increment's translation by it (a
///   lateral and vertical error of rotation_std times the distance), a translation error matters
///   in turns.
/// - Gyro scale and misalignment M (diagonal scale_std, off-diagonal misalignment_std): the
///   increment's rotation theta = Log(R_rel) comes out as (I + M) theta, a rotation error M theta.
/// The LiDAR's time offset is not here: livo-lio estimates it by default (calibration.lidar_time).
Mat6 heldCalibrationCovariance(const Pose3& T_rel, const HeldCalibration& held);

/// A cross-covariance C = Cov(δx, δy) carried through updates of x that took its covariance from
/// P_prior to P_post without touching y: C <- A C with P_post = A P_prior, A = Π (I - K_i H_i),
/// i.e. P_post P_prior^-1 C (exact for Kalman updates and compositions of them). States of zero
/// prior variance (a calibration held fixed) have zero rows in C and are left out of the solve.
CloneCrossCovariance carriedThroughUpdate(const StateCovariance& P_prior, const StateCovariance& P_post,
                                          const CloneCrossCovariance& C);

/// The same for states y the update does not measure but estimates (the Kalman update of the
/// filter augmented with y): with Y = P_prior^-1 C over the estimated states and dx = x_post ⊟ x_prior,
///   C <- P_post Y,  y <- y + Y^T dx,  Cov(y) <- Cov(y) - C^T Y + Y^T P_post Y,
/// and a state z beside them that is only considered (a cloned pose: its value is fixed) keeps
/// its covariance while Cov(y, z) <- Cov(y, z) - C_y^T Y_z + Y_y^T P_post Y_z.
/// `C` is Cov(δx, [y z]); the result's `covariance_change` is the change of Cov([y z]) (z's own
/// block included, for the caller to leave out) and `mean_step` Y^T dx.
struct ConditionedBeside {
  Eigen::MatrixXd cross;              // the new Cov(δx, [y z])
  Eigen::VectorXd mean_step;          // Y^T dx
  Eigen::MatrixXd covariance_change;  // -C^T Y + Y^T P_post Y
};
ConditionedBeside conditionedOnUpdate(const StateCovariance& P_prior, const StateCovariance& P_post,
                                      const Eigen::MatrixXd& C, const StateVector& dx);

}  // namespace livo::lio
