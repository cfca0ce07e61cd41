// IMU initialisation: static start (gravity direction, gyro bias) and moving start.
#include <gtest/gtest.h>

#include <random>

#include "livo/imu_initializer.hpp"
#include "synthetic_world.hpp"

using namespace livo;
using namespace livo::lio;

namespace {
std::vector<ImuSample> window(const synth::Trajectory& traj, double t0, double t1, const synth::ImuErrorModel& err,
                              unsigned seed) {
  std::mt19937 rng(seed);
  return synth::simulateImu(traj, t0, t1, 200.0, 0, err, &rng);
}
}  // namespace

TEST(ImuInitializer, StaticStartRecoversGravityAndGyroBias) {
  auto traj = synth::roomTrajectory(2.0);  // still for 2 s, tilted (roll 0.02, pitch -0.03)
  synth::ImuErrorModel err;
  err.noise = ImuNoise{1.7e-4, 2.0e-3, 0, 0};
  err.gyro_bias = Vec3(0.004, -0.003, 0.002);
  const auto w = window(traj, 0.0, 1.0, err, 3);
  ImuInitOptions opts;
  opts.window_s = 1.0;
  ASSERT_TRUE(isStill(w, opts));
  const ImuInitResult r = initializeImu(w, opts);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_TRUE(r.static_start);
  EXPECT_EQ(r.last.utime, w.back().utime);
  // gyro bias within 4 standard errors of the mean (density / sqrt(T))
  EXPECT_LT((r.state.gyro_bias - err.gyro_bias).cwiseAbs().maxCoeff(), 4 * 1.7e-4 / std::sqrt(1.0));
  // gravity-aligned world: roll and pitch of the estimate equal the truth's
  const Mat3 R_true = traj.pose(0.0).linear();
  const Vec3 up_est = r.state.rot.transpose() * Vec3::UnitZ();
  const Vec3 up_true = R_true.transpose() * Vec3::UnitZ();
  EXPECT_LT(std::acos(std::min(1.0, up_est.dot(up_true))), 2e-4);
  EXPECT_NEAR(r.state.gravity.z(), -9.81, 1e-12);
  EXPECT_EQ(r.state.vel, Vec3::Zero());
  // covariance: positive definite, tighter than the moving start's
  EXPECT_EQ(Eigen::LLT<Mat18>(r.covariance).info(), Eigen::Success);
  EXPECT_LT(r.covariance(FilterState::kVel, FilterState::kVel), 1e-3);
}

TEST(ImuInitializer, StaticStartTakesTheAccelerometerErrorAlongUpFromGravitysMagnitude) {
  // At rest the specific force is gravity: a mean that exceeds the rig's 9.81 by 0.11 m/s^2 (a 1 %
  // scale error, room_hard's accelerometer) is that much error along up, which the filter would
  // otherwise learn only from the LiDAR's height, and integrate as a vertical acceleration until it
  // does (0.2 m in 2 s). Across up the error looks like a tilt and stays with its prior.
  auto traj = synth::roomTrajectory(2.0);  // still, tilted (roll 0.02, pitch -0.03)
  synth::ImuErrorModel err;
  err.noise = ImuNoise{1.7e-4, 2.9e-3, 0, 0};
  err.accel_bias = Vec3(0.03, -0.02, 0.11);
  const auto w = window(traj, 0.0, 0.5, err, 5);
  const ImuInitOptions opts;
  const ImuInitResult r = initializeImu(w, opts);
  ASSERT_TRUE(r.ok) << r.message;
  ASSERT_TRUE(r.static_start);
  const Vec3 up = r.state.rot.transpose() * Vec3::UnitZ();  // body frame
  const Mat3 Pb = r.covariance.block<3, 3>(FilterState::kAccelBias, FilterState::kAccelBias);
  const double sigma_up = std::sqrt(up.dot(Pb * up));
  EXPECT_LT(sigma_up, 0.01);
  EXPECT_GT(sigma_up, opts.static_up_bias_floor);
  // the estimate along up within 3 sigma of the planted error's component
  EXPECT_NEAR(r.state.accel_bias.dot(up), err.accel_bias.dot(up), 3.0 * sigma_up);
  EXPECT_LT((r.state.accel_bias - r.state.accel_bias.dot(up) * up).norm(), 1e-12);  // nothing across up
  const Vec3 across = up.unitOrthogonal();
  EXPECT_NEAR(across.dot(Pb * across), opts.accel_bias_std * opts.accel_bias_std, 1e-12);
  EXPECT_NEAR((Pb * up).dot(across), 0.0, 1e-12);
  EXPECT_EQ(Eigen::LLT<Mat18>(r.covariance).info(), Eigen::Success);
  // the state's specific force at rest is gravity's magnitude again: reading - bias = g up
  const Vec3 mean = [&] {
    Vec3 a = Vec3::Zero();
    for (const auto& s : w) a += s.accel / static_cast<double>(w.size());
    return a;
  }();
  EXPECT_NEAR((mean - r.state.accel_bias).norm(), opts.gravity, 1e-9);
}

TEST(ImuInitializer, MovingStartNeedsNoStillWindow) {
  auto traj = synth::roomTrajectory(0.0);
  synth::ImuErrorModel err;
  err.noise = ImuNoise{1.7e-4, 2.0e-3, 0, 0};
  const auto w = window(traj, 0.5, 1.0, err, 4);  // walking
  ImuInitOptions opts;
  ASSERT_FALSE(isStill(w, opts));

  opts.mode = ImuInitOptions::Mode::kStatic;
  EXPECT_FALSE(initializeImu(w, opts).ok);

  opts.mode = ImuInitOptions::Mode::kAuto;
  const ImuInitResult r = initializeImu(w, opts);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_FALSE(r.static_start);
  EXPECT_EQ(r.state.gyro_bias, Vec3::Zero());
  // direction from the averaged specific force: within the tilt the accelerations cause (< 0.1 rad)
  const Vec3 up_est = r.state.rot.transpose() * Vec3::UnitZ();
  const Vec3 up_true = traj.pose(1.0).linear().transpose() * Vec3::UnitZ();
  EXPECT_LT(std::acos(std::min(1.0, up_est.dot(up_true))), 0.1);
  EXPECT_NEAR(r.covariance(FilterState::kVel, FilterState::kVel), 1.0, 1e-12);
  EXPECT_EQ(Eigen::LLT<Mat18>(r.covariance).info(), Eigen::Success);
}

TEST(ImuInitializer, RejectsDegenerateInput) {
  ImuInitOptions opts;
  EXPECT_FALSE(initializeImu({}, opts).ok);
  std::vector<ImuSample> freefall(10);
  for (int i = 0; i < 10; ++i) freefall[i].utime = i * 5000;
  EXPECT_FALSE(initializeImu(freefall, opts).ok);
}
