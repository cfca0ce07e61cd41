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
