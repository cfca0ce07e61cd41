// IMU and wheel-encoder models: exact readings and noise statistics against the configured
// continuous-time parameters.
#include <gtest/gtest.h>

#include "livo/sim/imu_model.hpp"
#include "livo/sim/wheel_model.hpp"
#include "sim_test_support.hpp"

using namespace livo;
using namespace livo::sim;

TEST(ImuModel, StaticReadingIsGravityInTheBodyFrame) {
  Pose3 T = Pose3::Identity();
  T.linear() = so3::Exp(Vec3(0.3, -0.2, 1.0));
  test::ConstantMotion still(T);
  const ImuReading r = idealImuReading(still.at(1.0), 9.81, 7);
  EXPECT_LT((r.linear_acceleration - T.linear().transpose() * Vec3(0, 0, 9.81)).norm(), 1e-12);
  EXPECT_EQ(r.angular_velocity.norm(), 0.0);
  EXPECT_EQ(r.utime, 7);
}

TEST(ImuModel, WhiteNoiseAndBiasWalkFollowTheDensities) {
  ImuRig rig;
  rig.rate_hz = 400.0;
  rig.gyro_noise_density = 2e-3;
  rig.accel_noise_density = 3e-2;
  rig.gyro_random_walk = 0.0;
  rig.accel_random_walk = 0.0;
  const Vec3 bg(0.01, -0.02, 0.03), ba(0.1, 0.2, -0.3);
  ImuNoise noise(rig, bg, ba, Random(11, 1));
  const int n = 40000;
  Eigen::Array3d sum_g = Eigen::Array3d::Zero(), sq_g = sum_g, sum_a = sum_g, sq_a = sum_g;
  for (int i = 0; i < n; ++i) {
    ImuReading r;
    noise.apply(&r);
    sum_g += r.angular_velocity.array(), sq_g += r.angular_velocity.array().square();
    sum_a += r.linear_acceleration.array(), sq_a += r.linear_acceleration.array().square();
  }
  const Eigen::Array3d mean_g = sum_g / n, mean_a = sum_a / n;
  const Eigen::Array3d std_g = (sq_g / n - mean_g.square()).sqrt(), std_a = (sq_a / n - mean_a.square()).sqrt();
  const double sg = rig.gyro_noise_density * std::sqrt(rig.rate_hz),
               sa = rig.accel_noise_density * std::sqrt(rig.rate_hz);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(mean_g[i], bg[i], 4 * sg / std::sqrt(n));
    EXPECT_NEAR(mean_a[i], ba[i], 4 * sa / std::sqrt(n));
    EXPECT_NEAR(std_g[i] / sg, 1.0, 0.03);
    EXPECT_NEAR(std_a[i] / sa, 1.0, 0.03);
  }
}

TEST(ImuModel, BiasRandomWalkVarianceGrowsLinearly) {
  ImuRig rig;
  rig.rate_hz = 100.0;
  rig.gyro_noise_density = rig.accel_noise_density = 0.0;
  rig.gyro_random_walk = 1e-3;
  rig.accel_random_walk = 5e-2;
  // many independent runs of 20 s: Var(b(T)) = rw^2 T
  const int runs = 400, steps = 2000;
  double var_g = 0, var_a = 0;
  for (int k = 0; k < runs; ++k) {
    ImuNoise noise(rig, Vec3::Zero(), Vec3::Zero(), Random(5, 1, k));
    ImuReading r;
    for (int i = 0; i < steps; ++i) noise.apply(&r);
    var_g += noise.gyroBias().squaredNorm() / 3.0;
    var_a += noise.accelBias().squaredNorm() / 3.0;
  }
  const double T = steps / rig.rate_hz;
  EXPECT_NEAR(var_g / runs / (rig.gyro_random_walk * rig.gyro_random_walk * T), 1.0, 0.12);  // 1200 samples of chi^2
  EXPECT_NEAR(var_a / runs / (rig.accel_random_walk * rig.accel_random_walk * T), 1.0, 0.12);
}

TEST(WheelModel, DifferentialSpeedsOfATurningBase) {
  WheelRig rig;
  rig.track_width = 0.6;
  rig.T_I_B.translation() = Vec3(0.0, 0.0, -0.4);  // base below the IMU
  Pose3 T = Pose3::Identity();
  T.linear() = so3::Exp(Vec3(0, 0, 0.7));
  const double speed = 5.0, yaw_rate = 0.4;
  test::ConstantMotion motion(T, T.linear() * Vec3(speed, 0, 0), Vec3(0, 0, yaw_rate));
  const WheelReading r = idealWheelReading(motion.at(0.0), rig, 0);
  EXPECT_NEAR(r.left_speed, speed - 0.3 * yaw_rate, 1e-12);
  EXPECT_NEAR(r.right_speed, speed + 0.3 * yaw_rate, 1e-12);

  rig.speed_noise_std = 0.05;
  WheelNoise noise(rig, 1.02, 0.97, Random(2, 2));
  double sum_l = 0, sum_r = 0, sq_l = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    WheelReading w = r;
    noise.apply(&w);
    sum_l += w.left_speed, sum_r += w.right_speed, sq_l += w.left_speed * w.left_speed;
  }
  EXPECT_NEAR(sum_l / n, 1.02 * r.left_speed, 4 * 0.05 / std::sqrt(n));
  EXPECT_NEAR(sum_r / n, 0.97 * r.right_speed, 4 * 0.05 / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(sq_l / n - (sum_l / n) * (sum_l / n)) / 0.05, 1.0, 0.03);
}
