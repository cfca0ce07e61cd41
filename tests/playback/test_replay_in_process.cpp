// In-process replay on memq:// runs every handler to completion before the next message.
#include <fstream>

#include <gtest/gtest.h>

#include "livo/node.hpp"
#include "livo/playback/playback.hpp"
#include "test_log.hpp"

using namespace livo;
using namespace livo::playback;

TEST(ReplayInProcess, DeliversEverythingInLogOrderThroughNodes) {
  const std::string path = playback_test::makeLog("inproc", 3.0);
  lcm::LCM lcm("memq://");
  NodeOptions o;
  o.name = "consumer";
  o.quiet = true;
  Node node(lcm, o);
  std::vector<std::string> order;
  node.subscribe<imu_t>("IMU", [&](const imu_t&) { order.push_back("IMU"); });
  node.subscribe<point_cloud_t>("LIDAR", [&](const point_cloud_t& c) {
    order.push_back("LIDAR");
    node.publish("ECHO", c);  // published from a handler: delivered before the next log message
  });
  int echoes_before_next = 0;
  node.subscribe<point_cloud_t>("ECHO", [&](const point_cloud_t&) {
    EXPECT_EQ(order.back(), "LIDAR");
    ++echoes_before_next;
  });
  LogSource src(path, {});
  EXPECT_EQ(replayInProcess(src, lcm), 330);
  EXPECT_EQ(node.handled("IMU"), 300);
  EXPECT_EQ(node.handled("LIDAR"), 30);
  EXPECT_EQ(echoes_before_next, 30);
  ASSERT_EQ(order.size(), 330u);
  EXPECT_EQ(order[5], "IMU");
  EXPECT_EQ(order[6], "LIDAR");  // LIDAR at i % 10 == 5 follows its IMU sample
}

TEST(Playback, DescribesWhereTheLockstepWaitedLongestFirst) {
  std::map<std::string, livo::playback::LockstepWaits> waits;
  waits["IMU"] = {6001, 900, 4.05, {{"lio", 1.97}, {"vio", 0.92}}};
  waits["LIDAR"] = {300, 300, 0.24, {{"lio", 0.24}}};
  waits["GROUND_TRUTH"] = {3001, 0, 0.0, {}};  // never waited for: left out
  waits["CAMERA"] = {600, 2, 0.004, {{"", 0.004}}};
  const std::vector<std::string> lines = livo::playback::describeWaits(waits);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "IMU: 900 of 6001 waited for, 4.05 s (lio 1.97, vio 0.92)");
  EXPECT_EQ(lines[1], "LIDAR: 300 of 300 waited for, 0.24 s (lio 0.24)");
  EXPECT_EQ(lines[2], "CAMERA: 2 of 600 waited for, 0.00 s (? 0.00)");
  EXPECT_EQ(livo::playback::describeWaits(waits, 1).size(), 1u);
}

// --clock-file: a supervisor (run_pipeline.sh --kill) reads the log seconds replayed so far.
TEST(Playback, KeepsTheLogSecondsReplayedInTheClockFile) {
  const std::string path = playback_test::makeLog("clock", 2.0);
  PlaybackOptions o;
  o.log = path;
  o.out_log = livo_test::tempPath("clock_out.lcmlog");
  o.clock_file = livo_test::tempPath("clock.txt");
  o.quiet = true;
  const PlaybackResult r = runPlayback(o, nullptr);
  ASSERT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(r.published, 220);
  std::ifstream f(o.clock_file);
  double log_s = -1.0;
  ASSERT_TRUE(f >> log_s) << "no number in " << o.clock_file;
  EXPECT_DOUBLE_EQ(log_s, 1.99);  // the last event, 199 IMU periods after the first
  EXPECT_FALSE(std::ifstream(o.clock_file + ".tmp").good()) << "the temporary file was renamed";

  o.clock_file = "/nonexistent-dir/clock.txt";  // a clock nobody can write is an error, not a silent gap
  EXPECT_THROW(runPlayback(o, nullptr), std::runtime_error);
}
