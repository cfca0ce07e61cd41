#include <gtest/gtest.h>

#include <deque>
#include <vector>

#include "livo/start_state_prior.hpp"

using livo::ImuSample;

namespace {
std::deque<ImuSample> samplesEvery(int64_t step_us, int64_t from, int64_t to) {
  std::deque<ImuSample> imu;
  for (int64_t t = from; t <= to; t += step_us) imu.push_back({t, livo::Vec3::Zero(), livo::Vec3(0.0, 0.0, 9.81)});
  return imu;
}
ImuSample at(int64_t utime) {
  ImuSample s;
  s.utime = utime;
  return s;
}
}  // namespace

TEST(StartStatePrior, TheWindowHoldsTheSamplesOfItsSpanEndsIncluded) {
  const std::deque<ImuSample> imu = samplesEvery(100'000, 0, 2'000'000);
  const std::vector<ImuSample> w = livo::imuStartWindow(imu, 1'500'000, 0.5);
  ASSERT_EQ(w.size(), 6u);
  EXPECT_EQ(w.front().utime, 1'000'000);
  EXPECT_EQ(w.back().utime, 1'500'000);
  EXPECT_TRUE(livo::startWindowFilled(w, 0.5));
}

TEST(StartStatePrior, AWindowIsFilledFromTwoSamplesOverEightyPercentOfItsSpan) {
  EXPECT_FALSE(livo::startWindowFilled({}, 0.5));
  EXPECT_FALSE(livo::startWindowFilled({at(0)}, 0.5));
  EXPECT_TRUE(livo::startWindowFilled({at(0), at(450'000)}, 0.5));
  EXPECT_FALSE(livo::startWindowFilled({at(0), at(350'000)}, 0.5));
  // the IMU started 0.3 s before the first sweep's end: not yet
  EXPECT_FALSE(
      livo::startWindowFilled(livo::imuStartWindow(samplesEvery(10'000, 1'200'000, 2'000'000), 1'500'000, 0.5), 0.5));
}

TEST(StartStatePrior, SigmasAtRestAndInMotion) {
  livo::ImuInitOptions init;
  const livo::StartStateSigmas rest = livo::restStartSigmas(init);
  EXPECT_EQ(rest.rotation, init.static_rot_std);
  EXPECT_EQ(rest.velocity, init.static_vel_std);
  EXPECT_EQ(rest.gyro_bias, livo::kRestGyroBiasStd);
  EXPECT_EQ(rest.accel_bias, init.accel_bias_std);
  const livo::StartStateSigmas moving = livo::movingStartSigmas(init);
  EXPECT_EQ(moving.rotation, init.moving_rot_std);
  EXPECT_EQ(moving.velocity, init.moving_vel_std);
  EXPECT_EQ(moving.gyro_bias, init.moving_gyro_bias_std);
  EXPECT_EQ(moving.accel_bias, init.accel_bias_std);
}

TEST(StartStatePrior, ThePoseInformationHoldsTheGauge) {
  const livo::Mat6 info = livo::startPoseInformation(0.1, 1e-4, 1e-3);
  livo::Vec6 diagonal;
  diagonal << 100.0, 100.0, 1e8, 1e6, 1e6, 1e6;
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(info(i, i), diagonal(i), 1e-6 * diagonal(i)) << i;
  EXPECT_EQ((info - livo::Mat6(info.diagonal().asDiagonal())).norm(), 0.0);
}
