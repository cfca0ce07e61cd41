#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>

#include "livo/report/sensor_gaps.hpp"
#include "livo/sensor_watch/gap_watch.hpp"
#include "temp_path.hpp"

using livo::sensor_watch::GapWatch;
using livo::sensor_watch::SensorGap;

namespace {

// IMU at 200 Hz and LIDAR at 10 Hz from `from_s` to `to_s` (wall seconds), stamps = wall + 100 s.
std::vector<SensorGap> feed(GapWatch& watch, double from_s, double to_s) {
  std::vector<SensorGap> gaps;
  for (int i = 0; from_s + i * 0.005 < to_s; ++i) {
    const double t = from_s + i * 0.005;
    if (auto g = watch.arrived("IMU", t, std::llround((t + 100.0) * 1e6))) gaps.push_back(*g);
    if (i % 20 == 0)
      if (auto g = watch.arrived("LIDAR", t, std::llround((t + 100.0) * 1e6))) gaps.push_back(*g);
  }
  return gaps;
}

}  // namespace

TEST(GapWatch, SilenceOfASecondIsAGapFromTheLastMessageToTheNext) {
  GapWatch watch({"IMU", "LIDAR"}, 1.0);
  EXPECT_TRUE(feed(watch, 0.0, 4.0).empty());
  EXPECT_TRUE(watch.newlySilent(4.5).empty());  // 0.5 s: not yet a gap
  const auto silent = watch.newlySilent(5.1);
  ASSERT_EQ(silent.size(), 2u);  // both, once each
  EXPECT_EQ(silent[0].channel, "IMU");
  EXPECT_NEAR(silent[0].from_s, 3.995, 1e-9);
  EXPECT_TRUE(silent[0].open);
  EXPECT_TRUE(watch.newlySilent(5.3).empty());
  const auto gaps = feed(watch, 5.5, 8.0);
  ASSERT_EQ(gaps.size(), 2u);
  EXPECT_EQ(gaps[0].channel, "IMU");
  EXPECT_NEAR(gaps[0].length(), 1.505, 1e-9);
  EXPECT_FALSE(gaps[0].open);
  EXPECT_EQ(gaps[0].stamp_before, 103995000);
  EXPECT_EQ(gaps[0].stamp_after, 105500000);
  EXPECT_EQ(gaps[1].channel, "LIDAR");
  EXPECT_NEAR(gaps[1].length(), 1.6, 1e-9);  // last sweep at 3.9 s
  EXPECT_TRUE(watch.finish(8.5).empty());    // the last messages were 0.5 s ago
}

TEST(GapWatch, OnlyWatchedChannelsAfterTheirFirstMessageAndOpenGapsAtTheEnd) {
  GapWatch watch({"IMU", "LIDAR"}, 1.0);
  EXPECT_TRUE(watch.newlySilent(30.0).empty());  // nothing heard yet: the sensors are not up
  EXPECT_FALSE(watch.arrived("CAMERA", 31.0, 0));
  EXPECT_FALSE(watch.arrived("IMU", 31.0, 0));
  EXPECT_FALSE(watch.arrived("CAMERA", 40.0, 0));  // not watched
  const auto open = watch.finish(40.0);
  ASSERT_EQ(open.size(), 2u);
  EXPECT_EQ(open[0].channel, "IMU");
  EXPECT_TRUE(open[0].open);
  EXPECT_FALSE(open[0].never);
  EXPECT_DOUBLE_EQ(open[0].length(), 9.0);
  EXPECT_EQ(open[1].channel, "LIDAR");  // never heard: from the start of the watch
  EXPECT_TRUE(open[1].never);
  EXPECT_DOUBLE_EQ(open[1].from_s, 0.0);
  EXPECT_DOUBLE_EQ(open[1].length(), 40.0);
  std::ostringstream line;
  livo::sensor_watch::writeGapLine(line, open[1]);
  EXPECT_EQ(line.str(), "LIDAR\t0.000\t40.000\t40.000\tnever\t-\t-\n");
  EXPECT_THROW(GapWatch({}, 1.0), std::invalid_argument);
  EXPECT_THROW(GapWatch({"IMU"}, 0.0), std::invalid_argument);
}

TEST(GapWatch, GapsFileReadByTheReport) {
  GapWatch watch({"IMU", "LIDAR"}, 1.0);
  const auto gaps = feed(watch, 0.0, 2.0), back = feed(watch, 3.5, 4.0);
  const std::string path = livo_test::tempPath("sensor_gaps.tsv");
  {
    std::ofstream out(path);
    out << "# channel\tfrom_s\t...\n";
    for (const auto& g : back) livo::sensor_watch::writeGapLine(out, g);
    for (const auto& g : watch.finish(6.0)) livo::sensor_watch::writeGapLine(out, g);
  }
  const auto rows = livo::report::readSensorGaps(path);
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0].channel, "IMU");
  EXPECT_EQ(rows[0].from_s, "1.995");
  EXPECT_EQ(rows[0].to_s, "3.500");
  EXPECT_EQ(rows[0].length_s, "1.505");
  EXPECT_FALSE(rows[0].open);
  EXPECT_EQ(rows[0].stamp_before, "101.995000");
  EXPECT_TRUE(rows[2].open);
  const std::string md = livo::report::sensorGapsMarkdown(rows);
  EXPECT_NE(md.find("## Sensor gaps"), std::string::npos);
  EXPECT_NE(md.find("| IMU | 1.995 | 3.500 | 1.505 | 101.995000 .. 103.500000 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| LIDAR | 3.900 | the stop (still silent) | 2.100 |"), std::string::npos) << md;
  EXPECT_NE(livo::report::sensorGapsMarkdown({}).find("None"), std::string::npos);
  {
    std::ofstream out(path);
    livo::sensor_watch::writeGapLine(out, livo::sensor_watch::SensorGap{"IMU", 0.0, 12.5, true, true, 0, 0});
  }
  const auto never = livo::report::readSensorGaps(path);
  ASSERT_EQ(never.size(), 1u);
  EXPECT_TRUE(never[0].never && never[0].open);
  EXPECT_NE(livo::report::sensorGapsMarkdown(never).find("| IMU | 0.000 | the stop (never heard) | 12.500 |"),
            std::string::npos);

  std::ofstream(path) << "IMU\t1.0\t2.0\n";
  EXPECT_THROW(livo::report::readSensorGaps(path), std::runtime_error);
  EXPECT_THROW(livo::report::readSensorGaps(path + ".missing"), std::runtime_error);
}
