// The factors of the sliding-window graphs (Ceres) of livo-lio-graph and livo-vio-feature. A
// state is five parameter blocks: the orientation q_W_I (quaternion, Eigen order x y z w, on
// RightQuaternionManifold: perturbed on the right, q Exp(dtheta), the convention of every
// information matrix here), the position p_W, the velocity v_W and the gyro and accelerometer
// biases.
#pragma once

#include <ceres/ceres.h>

#include "livo/imu_preintegration.hpp"
#include "livo/quaternion_manifold.hpp"
#include "livo/so3.hpp"
#include "livo/wheel_preintegration.hpp"

namespace livo {

/// A problem that owns none of its cost functions, losses or manifolds: the windows keep their
/// factors across optimisations and rebuild the problem each time.
ceres::Problem::Options nonOwningProblemOptions();

/// Solves a window's problem: dense Schur, one thread, silent, at most `iterations` iterations.
void solveWindow(ceres::Problem* problem, int iterations);

/// The pose W_T_I of a state's orientation block q (x y z w, normalised here) and position block p.
inline Pose3 poseFromBlocks(const double* q, const double* p) {
  return se3::fromRotationTranslation(Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix(),
                                      Vec3(p[0], p[1], p[2]));
}

/// The IMU preintegration between states i and j (9 residuals; blocks q_i p_i v_i bg_i ba_i q_j p_j v_j).
ceres::CostFunction* makeImuFactor(const ImuPreintegration& preintegration, const Vec3& gravity_W);

/// The bias random walk between i and j over dt (6 residuals; blocks bg_i ba_i bg_j ba_j).
ceres::CostFunction* makeBiasWalkFactor(double gyro_random_walk, double accel_random_walk, double dt);

/// A measured pose with its information in [dtheta (right), dp] (6 residuals; blocks q p).
ceres::CostFunction* makePoseFactor(const Pose3& measured, const Mat6& information);

/// A measured relative pose T_i_j (state j in the body frame of state i) with its information in
/// [dtheta (right, of R_i^T R_j), dp (frame i)] (6 residuals; blocks q_i p_i q_j p_j). The
/// residual is [Log(R_m^T R_i^T R_j), R_i^T (p_j - p_i) - p_m]; a rigid motion of the world
/// leaves it unchanged.
ceres::CostFunction* makeRelativePoseFactor(const Pose3& T_i_j, const Mat6& information);
/// The same with the measurement's scale s as a block (blocks q_i p_i q_j p_j s; the translation
/// residual R_i^T (p_j - p_i) - s p_m): a relative motion whose metric scale is not trusted.
ceres::CostFunction* makeScaledRelativePoseFactor(const Pose3& T_i_j, const Mat6& information);

/// A Gaussian prior on a 3-vector block (velocity, a bias): per-axis sigmas.
ceres::CostFunction* makeVectorPriorFactor(const Vec3& mean, const Vec3& sigma);
/// The same with a full covariance (symmetric positive definite), e.g. an accelerometer bias known
/// along "up" from gravity's magnitude at rest and only loosely across it.
ceres::CostFunction* makeCorrelatedVectorPriorFactor(const Vec3& mean, const Mat3& covariance);
/// The wheel scales' prior (2 residuals; block s).
ceres::CostFunction* makeWheelScalePrior(const Vec2& mean, double sigma);
/// The wheel mounting correction's prior (3 residuals; block δ): isotropic, sigma in radians.
ceres::CostFunction* makeWheelMountingPrior(const Vec3& mean, double sigma);
/// A Gaussian prior on a scalar block (1 residual).
ceres::CostFunction* makeScalarPriorFactor(double mean, double sigma);

/// The wheel preintegration between i and j (6 residuals; blocks q_i p_i q_j p_j).
ceres::CostFunction* makeWheelFactor(const WheelPreintegration& preintegration);
/// The same with the wheel scales [s_l, s_r] as a block (wheel_preintegration.hpp; blocks q_i p_i
/// q_j p_j s): the tyres' true radii over the nominal, estimated with the trajectory.
ceres::CostFunction* makeScaledWheelFactor(const WheelPreintegration& preintegration);

/// What a wheel factor estimates besides the poses (wheel_preintegration.hpp): the tyres' scales
/// [s_l, s_r] and the mounting correction δ of the wheel frame (3 entries, radians).
struct WheelCalibrationBlocks {
  bool scales = false;
  bool mounting = false;
};
/// The wheel preintegration between i and j with the blocks q_i p_i q_j p_j, then s if
/// `what.scales`, then δ if `what.mounting` (without either: makeWheelFactor's).
ceres::CostFunction* makeWheelFactor(const WheelPreintegration& preintegration, const WheelCalibrationBlocks& what);

}  // namespace livo
