#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "livo/sweep_timing.hpp"

using livo::LidarScan;
using livo::sweepEndOffset;
using livo::sweepTiming;

namespace {
LidarScan sweep(double sweep_duration, std::vector<float> offsets) {
  LidarScan s;
  s.utime = 1'000'000;
  s.sweep_duration = sweep_duration;
  s.time_offset = std::move(offsets);
  s.points.assign(s.time_offset.size(), livo::Vec3::Zero());
  return s;
}
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
}  // namespace

TEST(SweepTiming, EmptySweepEndsAtItsDurationOrAtItsStart) {
  EXPECT_EQ(sweepEndOffset(sweep(0.1, {})), 0.1);
  EXPECT_EQ(sweepEndOffset(sweep(0.0, {})), 0.0);
  const livo::SweepTiming t = sweepTiming(sweep(0.1, {}), 0.002);
  EXPECT_EQ(t.start_utime, 1'002'000);
  EXPECT_EQ(t.end_utime, 1'102'000);
  EXPECT_EQ(t.end_offset_s, 0.1);
  const livo::SweepTiming none = sweepTiming(sweep(std::nan(""), {}), 0.002);
  EXPECT_EQ(none.start_utime, 1'002'000);
  EXPECT_EQ(none.end_utime, 1'002'000);
}

TEST(SweepTiming, EndsAtTheLaterOfTheDurationAndTheLastOffset) {
  EXPECT_EQ(sweepEndOffset(sweep(0.1, {0.0f, 0.125f, 0.25f, 0.0625f})), 0.25);  // points past the duration
  EXPECT_EQ(sweepEndOffset(sweep(0.125, {0.0f, 0.0625f})), 0.125);              // the duration past the points
  EXPECT_EQ(sweepTiming(sweep(0.1, {0.0f, 0.25f}), 0.0).end_utime, 1'250'000);
}

TEST(SweepTiming, InvalidDurationsAreIgnored) {
  for (double d : {0.0, -0.1, std::nan(""), std::numeric_limits<double>::infinity(), 1.5, 1.0 + 1e-9})
    EXPECT_EQ(sweepEndOffset(sweep(d, {0.0f, 0.0625f})), 0.0625) << d;
  EXPECT_EQ(sweepEndOffset(sweep(1.0, {0.0625f})), 1.0);  // the cap itself is a valid duration
}

TEST(SweepTiming, NegativeNonFiniteAndTooLargeOffsetsDoNotMoveTheEnd) {
  EXPECT_EQ(sweepEndOffset(sweep(0.0, {-0.5f, -2.0f})), 0.0);
  EXPECT_EQ(sweepEndOffset(sweep(0.0, {-0.5f, 0.0625f, -2.0f})), 0.0625);
  EXPECT_EQ(sweepEndOffset(sweep(0.0, {kNaN, kInf, -kInf, 0.125f})), 0.125);
  EXPECT_EQ(sweepEndOffset(sweep(0.1, {0.25f, 1.5f, 1000.0f})), 0.25);  // beyond the 1 s cap: garbage
  EXPECT_EQ(sweepEndOffset(sweep(0.1, {0.25f, 1.0f})), 1.0);            // at the cap: kept
  EXPECT_EQ(sweepEndOffset(sweep(std::nan(""), {kNaN, -1.0f, 2.0f})), 0.0);
}

TEST(SweepTiming, TheEndIsRoundedOnceFromTheLidarOffsetPlusTheEndOffset) {
  // 0.4 µs + 0.4 µs: 1 µs rounded together (0 + 0 rounded apart); the start rounds 0.4 µs to 0
  LidarScan s = sweep(0.4e-6, {});
  s.utime = 0;
  const livo::SweepTiming t = sweepTiming(s, 0.4e-6);
  EXPECT_EQ(t.start_utime, 0);
  EXPECT_EQ(t.end_utime, 1);
  // a LiDAR clock ahead of the IMU's: a negative offset moves both back
  const livo::SweepTiming back = sweepTiming(sweep(0.1, {0.05f}), -0.003);
  EXPECT_EQ(back.start_utime, 997'000);
  EXPECT_EQ(back.end_utime, 1'097'000);
}
