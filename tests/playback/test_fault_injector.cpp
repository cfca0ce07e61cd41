// Every fault mode does exactly what it says, reproducibly for a seed.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "livo/imu_t.hpp"
#include "livo/playback/fault_injector.hpp"
#include "test_log.hpp"

using namespace livo;
using namespace livo::playback;
using playback_test::kT0;

namespace {

std::vector<LogEvent> run(const std::string& log, const std::vector<std::string>& faults, uint64_t seed,
                          FaultCounts* imu_counts = nullptr, FaultCounts* lidar_counts = nullptr) {
  std::vector<Fault> f;
  for (const auto& s : faults) f.push_back(parseFault(s));
  FaultInjector inj(f, seed);
  LogSource src(log, {});
  std::vector<LogEvent> out;
  while (auto e = src.next())
    for (auto& o : inj.push(std::move(*e), kT0)) out.push_back(std::move(o));
  for (auto& o : inj.flush()) out.push_back(std::move(o));
  if (imu_counts && inj.counts().count("IMU")) *imu_counts = inj.counts().at("IMU");
  if (lidar_counts && inj.counts().count("LIDAR")) *lidar_counts = inj.counts().at("LIDAR");
  return out;
}

std::vector<int64_t> imuStamps(const std::vector<LogEvent>& events) {
  std::vector<int64_t> t;
  for (const auto& e : events) {
    if (e.channel != "IMU") continue;
    imu_t m;
    EXPECT_EQ(m.decode(e.data.data(), 0, static_cast<int>(e.data.size())), static_cast<int>(e.data.size()));
    t.push_back(m.utime);
  }
  return t;
}

size_t countChannel(const std::vector<LogEvent>& events, const std::string& ch) {
  size_t n = 0;
  for (const auto& e : events) n += e.channel == ch;
  return n;
}

const std::string& testLog() {
  static const std::string path = playback_test::makeLog("faults", 20.0);  // 2000 IMU, 200 LIDAR
  return path;
}

}  // namespace

TEST(FaultInjector, NoFaultsIsIdentity) {
  const auto out = run(testLog(), {}, 1);
  LogSource src(testLog(), {});
  size_t i = 0;
  while (auto e = src.next()) {
    ASSERT_LT(i, out.size());
    EXPECT_EQ(out[i].data, e->data);
    EXPECT_EQ(out[i].channel, e->channel);
    ++i;
  }
  EXPECT_EQ(i, out.size());
}

TEST(FaultInjector, DropRemovesTheCountedFractionOnlyOnItsChannel) {
  FaultCounts c;
  const auto out = run(testLog(), {"drop:IMU:0.3"}, 7, &c);
  EXPECT_EQ(countChannel(out, "IMU") + c.dropped, 2000u);
  EXPECT_EQ(countChannel(out, "LIDAR"), 200u);
  // binomial(2000, 0.3): mean 600, sd 20.5; 5 sd
  EXPECT_NEAR(static_cast<double>(c.dropped), 600.0, 103.0);
  // what remains is in order and unchanged
  const auto t = imuStamps(out);
  EXPECT_TRUE(std::is_sorted(t.begin(), t.end()));
  // reproducible for a seed, different for another
  EXPECT_EQ(imuStamps(run(testLog(), {"drop:IMU:0.3"}, 7)), t);
  EXPECT_NE(imuStamps(run(testLog(), {"drop:IMU:0.3"}, 8)), t);
}

TEST(FaultInjector, DuplicateRepeatsMessagesInPlace) {
  FaultCounts c;
  const auto out = run(testLog(), {"duplicate:LIDAR:0.5"}, 3, nullptr, &c);
  EXPECT_EQ(countChannel(out, "LIDAR"), 200u + c.duplicated);
  EXPECT_GT(c.duplicated, 50);
  size_t adjacent = 0;
  for (size_t i = 1; i < out.size(); ++i) adjacent += out[i].channel == "LIDAR" && out[i].data == out[i - 1].data;
  EXPECT_EQ(adjacent, static_cast<size_t>(c.duplicated));
}

TEST(FaultInjector, DelayReleasesLateByTheGivenTime) {
  FaultCounts c;
  const auto out = run(testLog(), {"delay:IMU:0.1:0.05"}, 5, &c);
  EXPECT_EQ(countChannel(out, "IMU"), 2000u);
  EXPECT_GT(c.delayed, 100);
  // A delayed message (stamp below the newest already out) is released just before the first
  // in-order message stamped at or after its stamp + 50 ms, and not earlier.
  int late = 0;
  int64_t newest = 0;
  for (size_t i = 0; i < out.size(); ++i) {
    if (out[i].utime >= newest) {
      newest = out[i].utime;
      continue;
    }
    ++late;
    EXPECT_LT(newest, out[i].utime + 50000);
    size_t k = i + 1;
    while (k < out.size() && out[k].utime < newest) ++k;  // other delayed ones released with it
    if (k < out.size()) {
      EXPECT_GE(out[k].utime, out[i].utime + 50000);
    }
  }
  EXPECT_EQ(late, c.delayed);
  const auto t = imuStamps(out);
  EXPECT_FALSE(std::is_sorted(t.begin(), t.end()));
}

TEST(FaultInjector, ReorderSwapsWithTheNextMessageOfTheChannel) {
  FaultCounts c;
  const auto out = run(testLog(), {"reorder:IMU:0.2"}, 11, &c);
  const auto t = imuStamps(out);
  ASSERT_EQ(t.size(), 2000u);
  int inversions = 0;
  for (size_t i = 0; i + 1 < t.size(); ++i) {
    if (t[i] > t[i + 1]) {
      ++inversions;
      EXPECT_EQ(t[i] - t[i + 1], 10000);  // neighbours swapped, nothing else
    }
  }
  EXPECT_EQ(inversions, c.reordered);
  EXPECT_GT(c.reordered, 200);
}

TEST(FaultInjector, CorruptChangesBytesSoDecodingFailsOrDiffers) {
  FaultCounts c;
  const auto out = run(testLog(), {"corrupt:IMU:0.25"}, 2, &c);
  const auto clean = run(testLog(), {}, 2);
  ASSERT_EQ(out.size(), clean.size());
  int changed = 0;
  for (size_t i = 0; i < out.size(); ++i) changed += out[i].data != clean[i].data;
  EXPECT_EQ(changed, c.corrupted);
  EXPECT_NEAR(c.corrupted, 500, 100);
}

TEST(FaultInjector, NanPointsOnlyInClouds) {
  FaultCounts c;
  const auto out = run(testLog(), {"nan:LIDAR:0.5"}, 4, nullptr, &c);
  int clouds_with_nan = 0, nan_points = 0, points = 0;
  for (const auto& e : out) {
    if (e.channel != "LIDAR") continue;
    point_cloud_t pc;
    ASSERT_EQ(pc.decode(e.data.data(), 0, static_cast<int>(e.data.size())), static_cast<int>(e.data.size()));
    int n = 0;
    for (int i = 0; i < pc.num_points; ++i)
      n += !std::isfinite(pc.x[i]) || !std::isfinite(pc.y[i]) || !std::isfinite(pc.z[i]);
    clouds_with_nan += n > 0;
    nan_points += n;
    points += pc.num_points;
  }
  EXPECT_EQ(clouds_with_nan, c.nan_clouds);
  EXPECT_NEAR(c.nan_clouds, 100, 25);
  EXPECT_NEAR(static_cast<double>(nan_points) / (c.nan_clouds * 200), 0.1, 0.03);
}

TEST(FaultInjector, TimeJumpShiftsStampsFromTheGivenTime) {
  FaultCounts c;
  const auto out = run(testLog(), {"jump:IMU:5:2.5"}, 1, &c);
  const auto t = imuStamps(out);
  ASSERT_EQ(t.size(), 2000u);
  for (int i = 0; i < 2000; ++i) {
    const int64_t orig = kT0 + i * 10000;
    EXPECT_EQ(t[i], orig >= kT0 + 5000000 ? orig + 2500000 : orig);
  }
  EXPECT_EQ(c.time_shifted, 1500);
}

TEST(FaultInjector, CutRemovesAWindow) {
  FaultCounts c;
  const auto out = run(testLog(), {"cut:LIDAR:3:7"}, 1, nullptr, &c);
  for (const auto& e : out) {
    if (e.channel != "LIDAR") continue;
    const double t = (e.utime - kT0) * 1e-6;
    EXPECT_FALSE(t >= 3.0 && t < 7.0) << t;
  }
  EXPECT_EQ(c.cut, 40);
  EXPECT_EQ(countChannel(out, "LIDAR"), 160u);
  EXPECT_EQ(countChannel(out, "IMU"), 2000u);
}

TEST(FaultInjector, ParseErrors) {
  EXPECT_THROW(parseFault("drop:IMU"), std::invalid_argument);
  EXPECT_THROW(parseFault("drop:IMU:1.5"), std::invalid_argument);
  EXPECT_THROW(parseFault("explode:IMU:0.1"), std::invalid_argument);
  EXPECT_THROW(parseFault("delay:IMU:0.1"), std::invalid_argument);
  EXPECT_THROW(parseFault("cut:IMU:5:2"), std::invalid_argument);
  EXPECT_THROW(parseFault("nan:LIDAR:abc"), std::invalid_argument);
  const Fault f = parseFault("delay:CAMERA:0.25:0.1");
  EXPECT_EQ(f.kind, Fault::Kind::kDelay);
  EXPECT_EQ(f.channel, "CAMERA");
  EXPECT_DOUBLE_EQ(f.fraction, 0.25);
  EXPECT_DOUBLE_EQ(f.seconds, 0.1);
}

TEST(LogSource, FiltersByChannelAndWindow) {
  LogSourceOptions o;
  o.channels = "LID.*";
  o.start_s = 2.0;
  o.duration_s = 3.0;
  LogSource src(testLog(), o);
  int n = 0;
  while (auto e = src.next()) {
    EXPECT_EQ(e->channel, "LIDAR");
    const double t = (e->utime - kT0) * 1e-6;
    EXPECT_GE(t, 2.0);
    EXPECT_LE(t, 5.0);
    ++n;
  }
  EXPECT_EQ(n, 30);
  EXPECT_THROW(LogSource("/nonexistent.lcmlog", {}), std::runtime_error);
  LogSourceOptions bad;
  bad.channels = "(";
  EXPECT_THROW(LogSource(testLog(), bad), std::runtime_error);
}
