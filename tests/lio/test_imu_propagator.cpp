// IMU propagation (paper eqs. 3-8): F_x and F_w against numeric differentiation of the error-state
// map, the state against an analytic trajectory (noise-free IMU, first-order convergence in the
// step), and the covariance against a Monte Carlo of the noise it models.
#include <gtest/gtest.h>

#include <random>

#include "livo/lio/imu_propagator.hpp"
#include "synthetic_world.hpp"

using namespace livo;
using namespace livo::lio;

namespace {
// δx_{i+1} as a function of (δx_i, w_i): (x̂ ⊞ δx) ⊞ (dt f(x̂ ⊞ δx, u, w)) ⊟ (x̂ ⊞ dt f(x̂, u, 0)), over the
// navigation states (the first 18)
Vec18 errorMap(const FilterState& xh, const Vec18& dx, const Eigen::Matrix<double, 12, 1>& w, const Vec3& gyro,
               const Vec3& accel, double dt) {
  StateVector d = StateVector::Zero();
  d.head<FilterState::kNavDim>() = dx;
  const FilterState x = xh.boxplus(d);
  FilterState next = propagateState(x, gyro - w.segment<3>(0), accel - w.segment<3>(3), dt);
  next.gyro_bias += w.segment<3>(6) * dt;
  next.accel_bias += w.segment<3>(9) * dt;
  return next.boxminus(propagateState(xh, gyro, accel, dt)).head<FilterState::kNavDim>();
}
}  // namespace

TEST(ImuPropagator, JacobiansMatchNumericDifferentiation) {
  const FilterState x = synth::someState();
  const Vec3 gyro(0.4, -0.9, 1.7), accel(0.5, 2.0, 9.4);
  for (double dt : {0.005, 0.05}) {
    Mat18 Fx;
    Mat18x12 Fw;
    propagationJacobians(x, gyro, accel, dt, &Fx, &Fw);
    Mat18 Fx_num;
    Mat18x12 Fw_num;
    const double h = 1e-6;
    const Eigen::Matrix<double, 12, 1> w0 = Eigen::Matrix<double, 12, 1>::Zero();
    for (int i = 0; i < 18; ++i) {
      Vec18 d = Vec18::Zero();
      d[i] = h;
      Fx_num.col(i) = (errorMap(x, d, w0, gyro, accel, dt) - errorMap(x, -d, w0, gyro, accel, dt)) / (2 * h);
    }
    for (int i = 0; i < 12; ++i) {
      Eigen::Matrix<double, 12, 1> w = w0;
      w[i] = h;
      Fw_num.col(i) =
          (errorMap(x, Vec18::Zero(), w, gyro, accel, dt) - errorMap(x, Vec18::Zero(), -w, gyro, accel, dt)) / (2 * h);
    }
    EXPECT_LT((Fx - Fx_num).cwiseAbs().maxCoeff(), 1e-8) << "dt " << dt << "\n" << Fx - Fx_num;
    EXPECT_LT((Fw - Fw_num).cwiseAbs().maxCoeff(), 1e-8) << "dt " << dt << "\n" << Fw - Fw_num;
  }
}

TEST(ImuPropagator, NoiseCovarianceFromDensities) {
  const ImuNoise n{1e-3, 2e-2, 3e-4, 4e-3};
  const Mat12 Q = discreteNoiseCovariance(n, 0.005);
  EXPECT_DOUBLE_EQ(Q(0, 0), 1e-6 / 0.005);
  EXPECT_DOUBLE_EQ(Q(4, 4), 4e-4 / 0.005);
  EXPECT_DOUBLE_EQ(Q(8, 8), 9e-8 / 0.005);
  EXPECT_DOUBLE_EQ(Q(11, 11), 1.6e-5 / 0.005);
  EXPECT_EQ(Q(0, 1), 0.0);
}

namespace {
// Propagates the true state at t0 through exact IMU samples at rate_hz to t1; returns the error.
Vec6 propagationError(double rate_hz, double t0, double t1) {
  const auto traj = synth::roomTrajectory(0.0);
  const int64_t base = 1'000'000'000;
  std::mt19937 rng(1);
  const auto imu = synth::simulateImu(traj, t0, t1, rate_hz, base, synth::ImuErrorModel::exact(), &rng);
  ImuPropagator prop;
  prop.reset(traj.state(t0), StateCovariance::Identity() * 1e-6, imu.front());
  for (size_t i = 1; i < imu.size(); ++i) EXPECT_TRUE(prop.addSample(imu[i]));
  EXPECT_EQ(prop.utime(), base + static_cast<int64_t>(std::llround(t1 * 1e6)));
  const FilterState truth = traj.state(t1);
  Vec6 e;
  e.head<3>() = so3::Log(Mat3(truth.rot.transpose() * prop.state().rot));
  e.tail<3>() = prop.state().pos - truth.pos;
  return e;
}
}  // namespace

TEST(ImuPropagator, FollowsAnAnalyticTrajectory) {
  // 2 s of walking with turns (up to 1.5 m/s, 0.7 rad/s), exact IMU.
  const Vec6 e200 = propagationError(200.0, 1.0, 3.0);
  const Vec6 e1000 = propagationError(1000.0, 1.0, 3.0);
  const Vec6 e5000 = propagationError(5000.0, 1.0, 3.0);
  // At 200 Hz the Euler scheme of eq. (3) stays within 1 cm and 1 mrad over 2 s ...
  EXPECT_LT(e200.head<3>().norm(), 1e-3);
  EXPECT_LT(e200.tail<3>().norm(), 1e-2);
  // ... and the error is first order in the step: 5x smaller step, ~5x smaller error.
  const double r1 = e200.tail<3>().norm() / e1000.tail<3>().norm();
  const double r2 = e1000.tail<3>().norm() / e5000.tail<3>().norm();
  EXPECT_GT(r1, 4.0);
  EXPECT_LT(r1, 6.0);
  EXPECT_GT(r2, 4.0);
  EXPECT_LT(r2, 6.0);
  EXPECT_LT(e5000.tail<3>().norm(), 5e-4);
  EXPECT_LT(e5000.head<3>().norm(), 5e-5);
}

TEST(ImuPropagator, PropagateToInterpolatesBetweenSamples) {
  const auto traj = synth::roomTrajectory(0.0);
  const int64_t base = 0;
  std::mt19937 rng(1);
  const auto imu = synth::simulateImu(traj, 1.0, 1.1, 200.0, base, synth::ImuErrorModel::exact(), &rng);
  ImuPropagator a, b;
  a.reset(traj.state(1.0), StateCovariance::Identity() * 1e-6, imu[0]);
  b = a;
  // a: to the sample at 1.05 s; b: to 1.0525 then on to 1.055 through the next sample
  for (int i = 1; i <= 10; ++i) a.addSample(imu[i]);
  for (int i = 1; i <= 10; ++i) b.addSample(imu[i]);
  b.propagateTo(imu[10].utime + 2500, imu[11]);
  EXPECT_EQ(b.utime(), imu[10].utime + 2500);
  EXPECT_NEAR((b.lastSample().gyro - 0.5 * (imu[10].gyro + imu[11].gyro)).norm(), 0.0, 1e-12);
  const FilterState before = a.state();
  b.addSample(imu[11]);
  a.addSample(imu[11]);
  // Two half steps of eq. (3) with the interpolated sample m in between (inputs (s10 + m) / 2
  // and (m + s11) / 2) against one full step (input (s10 + s11) / 2): exactly known differences.
  const double h = 0.0025;
  const Vec3 g1 = 0.75 * imu[10].gyro + 0.25 * imu[11].gyro, g2 = 0.25 * imu[10].gyro + 0.75 * imu[11].gyro;
  const Vec3 a1 = 0.75 * imu[10].accel + 0.25 * imu[11].accel;
  const Mat3 R_half = before.rot * so3::Exp(g1 * h) * so3::Exp(g2 * h);
  EXPECT_LT(so3::Log(Mat3(R_half.transpose() * b.state().rot)).norm(), 1e-14);
  // position: the second half step sees the velocity after the first: p + v 2h + a1 h^2
  const Vec3 acc1 = before.rot * a1 + before.gravity;
  EXPECT_LT(((b.state().pos - a.state().pos) - acc1 * h * h).norm(), 1e-12);
  // and both agree with each other to second order in the step
  EXPECT_LT(so3::Log(Mat3(a.state().rot.transpose() * b.state().rot)).norm(), 1e-5);
  EXPECT_EQ(b.segments().size(), 12u);
  EXPECT_FALSE(b.addSample(imu[5]));  // older than the state
}

TEST(ImuPropagator, CovarianceMatchesMonteCarlo) {
  // Propagate the nominal state with exact inputs and many noisy copies; the spread of
  // (noisy ⊟ nominal) must match P (0.25 s at 200 Hz, large densities so noise dominates).
  const ImuNoise noise{0.01, 0.1, 0.001, 0.01};
  const double dt = 0.005;
  const int steps = 50, runs = 1500;
  const FilterState x0 = synth::someState();
  const Vec3 gyro(0.3, -0.4, 0.8), accel(0.3, 0.5, 9.9);
  ImuPropagator prop(noise);
  ImuSample s0;
  s0.utime = 0;
  s0.gyro = gyro;
  s0.accel = accel;
  prop.reset(x0, StateCovariance::Identity() * 1e-12, s0);
  for (int k = 1; k <= steps; ++k) {
    ImuSample s = s0;
    s.utime = k * 5000;
    prop.addSample(s);
  }
  std::mt19937 rng(42);
  std::normal_distribution<double> n01;
  Mat18 C = Mat18::Zero();
  for (int r = 0; r < runs; ++r) {
    FilterState x = x0;
    for (int k = 0; k < steps; ++k) {
      Vec3 ng, na, nbg, nba;
      for (int a = 0; a < 3; ++a) {
        ng[a] = noise.gyro_noise_density / std::sqrt(dt) * n01(rng);
        na[a] = noise.accel_noise_density / std::sqrt(dt) * n01(rng);
        nbg[a] = noise.gyro_random_walk / std::sqrt(dt) * n01(rng);
        nba[a] = noise.accel_random_walk / std::sqrt(dt) * n01(rng);
      }
      x = propagateState(x, gyro - ng, accel - na, dt);
      x.gyro_bias += nbg * dt;
      x.accel_bias += nba * dt;
    }
    const Vec18 e = x.boxminus(prop.state()).head<FilterState::kNavDim>();
    C += e * e.transpose() / runs;
  }
  const Mat18 P = prop.covariance().topLeftCorner<FilterState::kNavDim, FilterState::kNavDim>();
  // variances within 15 % (the standard error of a variance from 1500 runs is ~3.7 %)
  for (int i = 0; i < 15; ++i) EXPECT_NEAR(C(i, i) / P(i, i), 1.0, 0.15) << "state " << i;
  // the rotation-velocity and position-velocity correlations
  auto corr = [](const Mat18& M, int i, int j) { return M(i, j) / std::sqrt(M(i, i) * M(j, j)); };
  for (int i : {0, 1, 3, 4})
    for (int j : {6, 7, 8}) EXPECT_NEAR(corr(C, i, j), corr(P, i, j), 0.1) << i << "," << j;
}

// The sensors' calibration is constant: propagation keeps its values and its own covariance block
// exactly and carries its correlation with the navigation state through F_x, P = [A B; B^T C] ->
// [F_x A F_x^T + F_w Q F_w^T, F_x B; (F_x B)^T, C].
TEST(ImuPropagator, CalibrationIsConstantAndItsCorrelationFollowsTheNavigationState) {
  const ImuNoise noise{0.01, 0.1, 0.001, 0.01};
  const double dt = 0.005;
  const int steps = 20;
  FilterState x0 = synth::someState();
  x0.lidar = SensorCalibration{so3::Exp(Vec3(0.1, -0.2, 1.5)), Vec3(0.1, 0.0, 0.2), 0.003};
  x0.camera = SensorCalibration{so3::Exp(Vec3(-1.5, 0.1, 0.0)), Vec3(0.05, -0.02, 0.0), -0.01};
  std::mt19937 rng(5);
  std::normal_distribution<double> n01;
  StateCovariance A0;
  for (int i = 0; i < A0.size(); ++i) A0.data()[i] = 0.05 * n01(rng);
  const StateCovariance P0 = A0 * A0.transpose() + 1e-4 * StateCovariance::Identity();
  const Vec3 gyro(0.3, -0.4, 0.8), accel(0.3, 0.5, 9.9);
  ImuPropagator prop(noise);
  ImuSample s0;
  s0.utime = 0;
  s0.gyro = gyro;
  s0.accel = accel;
  prop.reset(x0, P0, s0);
  constexpr int n = FilterState::kNavDim, c = FilterState::kDim - FilterState::kNavDim;
  FilterState x = x0;
  Mat18 A = P0.topLeftCorner<n, n>();
  Eigen::Matrix<double, n, c> B = P0.topRightCorner<n, c>();
  for (int k = 1; k <= steps; ++k) {
    ImuSample s = s0;
    s.utime = k * 5000;
    ASSERT_TRUE(prop.addSample(s));
    Mat18 Fx;
    Mat18x12 Fw;
    propagationJacobians(x, gyro, accel, dt, &Fx, &Fw);
    A = Fx * A * Fx.transpose() + Fw * discreteNoiseCovariance(noise, dt) * Fw.transpose();
    B = Fx * B;
    x = propagateState(x, gyro, accel, dt);
  }
  const FilterState& xp = prop.state();
  EXPECT_EQ(xp.lidar.rot, x0.lidar.rot);
  EXPECT_EQ(xp.lidar.pos, x0.lidar.pos);
  EXPECT_EQ(xp.lidar.dt, x0.lidar.dt);
  EXPECT_EQ(xp.camera.rot, x0.camera.rot);
  EXPECT_EQ(xp.camera.pos, x0.camera.pos);
  EXPECT_EQ(xp.camera.dt, x0.camera.dt);
  const StateCovariance& P = prop.covariance();
  EXPECT_EQ((P.bottomRightCorner<c, c>()), (P0.bottomRightCorner<c, c>()));
  EXPECT_LT((P.topLeftCorner<n, n>() - A).cwiseAbs().maxCoeff(), 1e-12 * A.cwiseAbs().maxCoeff());
  EXPECT_LT((P.topRightCorner<n, c>() - B).cwiseAbs().maxCoeff(), 1e-12 * B.cwiseAbs().maxCoeff());
  EXPECT_EQ((P.bottomLeftCorner<c, n>()), (P.topRightCorner<n, c>().transpose()));
  // the correlation moved: a rotation-calibration correlation reaches the position through the velocity
  EXPECT_GT((B - P0.topRightCorner<n, c>()).cwiseAbs().maxCoeff(), 1e-4);
}

// The gyro's scale and misalignment errors are modelled as a rate noise whose density makes the
// attitude spread after one window (the sweep period, between two LiDAR updates) equal to that of
// the systematic error M w T of a gyro drawn with those 1-sigmas: checked against such draws.
TEST(ImuPropagator, ScaleAndMisalignmentSpreadMatchesDrawnGyrosOverOneWindow) {
  ImuNoise noise{0.0, 0.0, 0.0, 0.0};
  noise.gyro_scale_std = 0.01;
  noise.gyro_misalignment_std = 0.007;
  noise.systematic_error_window_s = 0.1;
  const Mat12 Q0 = discreteNoiseCovariance(noise, 0.005);
  EXPECT_EQ((Q0.block<3, 3>(0, 0).norm()), 0.0) << "no rate, no systematic error";

  const double dt = 0.005;
  const int steps = 20;  // one window
  const Vec3 gyro(0.2, -0.3, 1.1);
  FilterState x0 = synth::someState();
  x0.gyro_bias.setZero();
  ImuPropagator prop(noise);
  ImuSample s0;
  s0.gyro = gyro;
  s0.accel = Vec3(0.0, 0.0, 9.81);
  prop.reset(x0, StateCovariance::Identity() * 1e-14, s0);
  for (int k = 1; k <= steps; ++k) {
    ImuSample s = s0;
    s.utime = k * 5000;
    prop.addSample(s);
  }
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  const int runs = 4000;
  Mat3 C = Mat3::Zero();
  for (int r = 0; r < runs; ++r) {
    Mat3 M;  // measured = (I + M) true
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) M(i, j) = (i == j ? noise.gyro_scale_std : noise.gyro_misalignment_std) * n01(rng);
    const Vec3 truth = (Mat3::Identity() + M).inverse() * gyro;
    FilterState x = x0;
    for (int k = 0; k < steps; ++k) x = propagateState(x, truth, s0.accel, dt);
    const Vec3 e = so3::Log(Mat3(prop.state().rot.transpose() * x.rot));
    C += e * e.transpose() / runs;
  }
  const Mat3 P = prop.covariance().block<3, 3>(FilterState::kRot, FilterState::kRot);
  // the standard error of a variance from 4000 draws is ~2 %
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(C(i, i) / P(i, i), 1.0, 0.08) << "axis " << i;
  // the yaw axis turns fastest: its spread is mostly the scale error, 1 % of the 0.11 rad turned
  EXPECT_NEAR(std::sqrt(P(2, 2)) / (std::hypot(0.01 * 1.1, 0.007 * std::hypot(0.2, 0.3)) * 0.1), 1.0, 0.01);
}

// An external update (the camera hand-off) moves the state; the sweep's recorded trajectory moves
// rigidly with it, so undistortion relative to the new state is unchanged.
TEST(ImuPropagator, TransformSegmentsKeepsTheTrajectoryRelativeToTheState) {
  const auto traj = synth::roomTrajectory(0.0);
  std::mt19937 rng(2);
  const auto imu = synth::simulateImu(traj, 2.0, 2.1, 200.0, 0, synth::ImuErrorModel::exact(), &rng);
  ImuPropagator p;
  p.reset(traj.state(2.0), StateCovariance::Identity() * 1e-6, imu[0]);
  for (size_t i = 1; i < imu.size(); ++i) p.addSample(imu[i]);
  const std::vector<ImuSegment> before = p.segments();
  const FilterState x0 = p.state();
  const Pose3 T = se3::fromRotationTranslation(so3::Exp(Vec3(0.01, -0.02, 0.03)), Vec3(0.05, -0.04, 0.02));
  p.transformSegments(T);
  ASSERT_EQ(p.segments().size(), before.size());
  const Mat3 R_new = T.linear() * x0.rot;
  const Vec3 p_new = T.linear() * x0.pos + T.translation();
  for (size_t i = 0; i < before.size(); ++i) {
    const ImuSegment& a = before[i];
    const ImuSegment& b = p.segments()[i];
    // relative pose to the (moved) state is what it was
    EXPECT_LT(so3::Log(Mat3((x0.rot.transpose() * a.rot).transpose() * (R_new.transpose() * b.rot))).norm(), 1e-12);
    EXPECT_LT((x0.rot.transpose() * (a.pos - x0.pos) - R_new.transpose() * (b.pos - p_new)).norm(), 1e-12);
    EXPECT_LT((x0.rot.transpose() * a.vel - R_new.transpose() * b.vel).norm(), 1e-12);
    EXPECT_LT((x0.rot.transpose() * a.acc_world - R_new.transpose() * b.acc_world).norm(), 1e-12);
    EXPECT_EQ(a.omega, b.omega);
  }
}
