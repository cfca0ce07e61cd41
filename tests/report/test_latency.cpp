// Real-time latency (processes/report/README.md, "Latency"): livo-record's arrival log, the nodes'
// LIVO_LATENCY_TRACE lines, and the figures livo-report computes from them on hand-made logs with
// known arrival times (so known percentiles and known parts).
#include <cstdlib>
#include <fstream>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "livo/imu_t.hpp"
#include "livo/node.hpp"
#include "livo/odometry_t.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/record/recorder.hpp"
#include "livo/report/latency.hpp"
#include "livo/report/run_report.hpp"
#include "temp_path.hpp"

namespace livo::report {
namespace {

constexpr int64_t kWall = 1'800'000'000'000'000;  // the wall clock when the sensor clock is 0

void drain(lcm::LCM& lcm) {
  while (lcm.handleTimeout(0) > 0) {
  }
}

TEST(LatencyPercentile, NearestRank) {
  std::vector<double> v;
  for (int i = 100; i >= 1; --i) v.push_back(i);  // 1..100, unsorted
  EXPECT_DOUBLE_EQ(nearestRankPercentile(v, 0.5), 50.0);
  EXPECT_DOUBLE_EQ(nearestRankPercentile(v, 0.99), 99.0);
  EXPECT_DOUBLE_EQ(nearestRankPercentile(v, 1.0), 100.0);
  EXPECT_DOUBLE_EQ(nearestRankPercentile({7.0, 3.0, 5.0, 1.0}, 0.5), 3.0);  // rank ceil(2) = 2
  EXPECT_DOUBLE_EQ(nearestRankPercentile({7.0, 3.0, 5.0, 1.0}, 0.99), 7.0);
  EXPECT_DOUBLE_EQ(nearestRankPercentile({4.0}, 0.01), 4.0);
  EXPECT_THROW(nearestRankPercentile({}, 0.5), std::invalid_argument);
  EXPECT_THROW(nearestRankPercentile({1.0}, 0.0), std::invalid_argument);
  EXPECT_THROW(nearestRankPercentile({1.0}, 1.5), std::invalid_argument);
}

// 2 s of a replay: IMU at 200 Hz and 10 Hz sweeps published when their stamps are due (a sweep at
// its start, as the simulator's logs), images at 20 Hz half a period off the sweeps.
std::vector<Arrival> sensorArrivals() {
  std::vector<Arrival> a;
  for (int64_t t = 0; t <= 2'000'000; t += 5000) a.push_back({"IMU", "livo.imu_t", t, t, kWall + t});
  for (int64_t t = 0; t < 2'000'000; t += 100'000)
    a.push_back({"LIDAR", "livo.point_cloud_t", t, t + 100'000, kWall + t});
  for (int64_t t = 25'000; t < 2'000'000; t += 50'000) a.push_back({"CAMERA", "livo.image_t", t, t, kWall + t + 300});
  return a;
}

TEST(Latency, KnownArrivalsGiveKnownPercentilesAndParts) {
  std::vector<Arrival> arrivals = sensorArrivals();
  std::vector<PublishTrace> traces;
  // the odometry of sweep k (ending at (k+1) 100 ms) arrives 10 + k ms after its end; lio's handler
  // was set off by the IMU 5 ms after the end, received 6 ms after, started 1 ms later, and
  // published 1 ms before the recorder got it
  for (int k = 0; k < 19; ++k) {
    const int64_t end = (k + 1) * 100'000, arrival = kWall + end + 10'000 + k * 1000;
    arrivals.push_back({"ODOMETRY", "livo.odometry_t", end, end, arrival});
    traces.push_back(
        {"lio", "ODOMETRY", end, "IMU", end + 5000, kWall + end + 6000, kWall + end + 7000, arrival - 1000});
  }
  // the posterior of the image at 25 ms + 50 ms j: vio's handler was set off by lio's STATE_PRIOR
  for (int j = 0; j < 4; ++j) {
    const int64_t t = 25'000 + j * 50'000, arrival = kWall + t + 300 + 20'000;
    arrivals.push_back({"STATE_POSTERIOR", "livo.filter_state_t", t, t, arrival});
    traces.push_back(
        {"vio", "STATE_POSTERIOR", t, "STATE_PRIOR", t, kWall + t + 300 + 4000, kWall + t + 300 + 4000, arrival});
  }
  // a posterior of no image (stamped past the last) is unmatched, not a figure
  arrivals.push_back({"STATE_POSTERIOR", "livo.filter_state_t", 3'000'000, 3'000'000, kWall + 3'010'000});

  const std::vector<ChannelLatency> out = computeLatency(arrivals, traces, defaultLatencySpecs());
  ASSERT_EQ(out.size(), 2u);  // no COLORED_CLOUD arrived
  const ChannelLatency& odo = out[0];
  EXPECT_EQ(odo.channel, "ODOMETRY");
  EXPECT_EQ(odo.publisher, "lio");
  EXPECT_EQ(odo.messages, 19);
  EXPECT_EQ(odo.unmatched, 0);
  EXPECT_EQ(odo.traced, 19);
  EXPECT_NEAR(odo.p50_ms, 19.0, 1e-9);  // 10..28 ms: the 10th
  EXPECT_NEAR(odo.p99_ms, 28.0, 1e-9);
  EXPECT_NEAR(odo.max_ms, 28.0, 1e-9);
  EXPECT_NEAR(odo.mean.sensors_ms, 5.0, 1e-9);       // the IMU sample 5 ms past the end
  EXPECT_NEAR(odo.mean.late_sensors_ms, 1.0, 1e-9);  // reached lio 1 ms after the recorder saw its time due
  EXPECT_NEAR(odo.mean.handoff_ms, 0.0, 1e-9);
  EXPECT_NEAR(odo.mean.queueing_ms, 1.0, 1e-9);
  EXPECT_NEAR(odo.mean.processing_ms, 11.0, 1e-9);  // 10 + k - 1 - 7 for k = 0..18: 11 on average
  EXPECT_NEAR(odo.mean.delivery_ms, 1.0, 1e-9);
  EXPECT_NEAR(odo.slowest.processing_ms, 20.0, 1e-9);  // the slowest: 28 ms = 5 + 1 + 1 + 20 + 1
  EXPECT_TRUE(odo.handoffs.empty());

  const ChannelLatency& post = out[1];
  EXPECT_EQ(post.channel, "STATE_POSTERIOR");
  EXPECT_EQ(post.publisher, "vio");
  EXPECT_EQ(post.messages, 4);
  EXPECT_EQ(post.unmatched, 1);
  EXPECT_NEAR(post.p50_ms, 20.0, 1e-9);
  EXPECT_NEAR(post.mean.handoff_ms, 4.0, 1e-9);  // waiting for lio's prior
  EXPECT_NEAR(post.mean.sensors_ms, 0.0, 1e-9);
  EXPECT_NEAR(post.mean.processing_ms, 16.0, 1e-9);
  ASSERT_EQ(post.handoffs.count("STATE_PRIOR"), 1u);
  EXPECT_EQ(post.handoffs.at("STATE_PRIOR"), 4);
}

TEST(Latency, ASweepIsDueWhenBothItsMessageAndItsEndHaveArrived) {
  // a driver that publishes the sweep 30 ms after its end (a live LiDAR): the sweep's message is
  // what the latency counts from, not the IMU at its end
  std::vector<Arrival> arrivals;
  for (int64_t t = 0; t <= 300'000; t += 5000) arrivals.push_back({"IMU", "livo.imu_t", t, t, kWall + t});
  arrivals.push_back({"LIDAR", "livo.point_cloud_t", 100'000, 200'000, kWall + 230'000});
  arrivals.push_back({"ODOMETRY", "livo.odometry_t", 200'000, 200'000, kWall + 245'000});
  // a coloured cloud on a scan and one on an image, each from the nearer stamp
  arrivals.push_back({"CAMERA", "livo.image_t", 150'000, 150'000, kWall + 151'000});
  arrivals.push_back({"COLORED_CLOUD", "livo.colored_cloud_t", 200'002, 200'002, kWall + 260'000});
  arrivals.push_back({"COLORED_CLOUD", "livo.colored_cloud_t", 150'000, 150'000, kWall + 170'000});
  const auto out = computeLatency(arrivals, {}, defaultLatencySpecs());
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NEAR(out[0].max_ms, 15.0, 1e-9);
  EXPECT_EQ(out[0].traced, 0);  // no trace: figures without parts
  EXPECT_EQ(out[1].channel, "COLORED_CLOUD");
  EXPECT_EQ(out[1].publisher, "colour");
  ASSERT_EQ(out[1].latencies_ms.size(), 2u);
  EXPECT_NEAR(out[1].latencies_ms[0], 30.0, 1e-9);
  EXPECT_NEAR(out[1].latencies_ms[1], 19.0, 1e-9);
}

TEST(Latency, TimingJsonAndReportSection) {
  std::vector<Arrival> arrivals = sensorArrivals();
  std::vector<PublishTrace> traces;
  for (int k = 0; k < 10; ++k) {
    const int64_t end = (k + 1) * 100'000, arrival = kWall + end + 20'000;
    arrivals.push_back({"ODOMETRY", "livo.odometry_t", end, end, arrival});
    // set off by vio's answer (lio waited for it), published at once
    traces.push_back(
        {"lio", "ODOMETRY", end, "STATE_POSTERIOR", end - 25'000, kWall + end + 15'000, kWall + end + 15'000, arrival});
  }
  nlohmann::json timing = {{"lio", {{"messages", 10}, {"median_ms", 5.0}}}};
  addLatency(computeLatency(arrivals, traces, defaultLatencySpecs()), &timing);
  const nlohmann::json& l = timing["lio"]["latency"]["ODOMETRY"];
  EXPECT_EQ(timing["lio"]["messages"], 10);  // the process's own fields stay
  EXPECT_EQ(l["from"], "sweep end");
  EXPECT_EQ(l["messages"], 10);
  EXPECT_DOUBLE_EQ(l["p50_ms"].get<double>(), 20.0);
  EXPECT_DOUBLE_EQ(l["p99_ms"].get<double>(), 20.0);
  EXPECT_DOUBLE_EQ(l["max_ms"].get<double>(), 20.0);
  EXPECT_DOUBLE_EQ(l["where_ms"]["mean"]["waiting_for_handoff"].get<double>(), 15.0);
  EXPECT_DOUBLE_EQ(l["where_ms"]["mean"]["processing"].get<double>(), 5.0);
  EXPECT_EQ(l["handoffs"]["STATE_POSTERIOR"], 10);

  const std::string md = latencyMarkdown(timing);
  EXPECT_NE(md.find("## Latency"), std::string::npos) << md;
  EXPECT_NE(md.find("| ODOMETRY | lio | sweep end | 10 | 20.0 | 20.0 | 20.0 |"), std::string::npos) << md;
  EXPECT_NE(md.find("15.0 / 15.0 (STATE_POSTERIOR 10x)"), std::string::npos) << md;
  ReportInputs in;
  in.timing = timing;
  EXPECT_NE(reportMarkdown(in).find("## Latency"), std::string::npos);
  // a lockstep run has none
  EXPECT_EQ(latencyMarkdown(nlohmann::json{{"lio", {{"messages", 10}}}}), "");
}

TEST(Latency, MalformedFilesAreNamed) {
  const std::string path = livo_test::tempPath("arrivals_bad.tsv");
  std::ofstream(path) << "# channel\ttype\tutime\tend_utime\tarrival_us\nIMU\tlivo.imu_t\t5\t5\tsoon\n";
  try {
    readArrivals(path);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("arrivals_bad.tsv:2: 'soon' is not a whole number"), std::string::npos)
        << e.what();
  }
  std::ofstream(path) << "ODOMETRY\t5\tIMU\n";
  EXPECT_THROW(readPublishTraces(path, "lio"), std::runtime_error);
  EXPECT_THROW(readArrivals(livo_test::tempPath("missing.tsv")), std::runtime_error);
}

TEST(Latency, RecorderArrivalsAndNodeTraceOnTheBus) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  const std::string arrivals_path = livo_test::tempPath("arrivals.tsv");
  const std::string trace_path = livo_test::tempPath("lio.trace.tsv");
  ::setenv("LIVO_LATENCY_TRACE", trace_path.c_str(), 1);
  NodeOptions o;
  o.name = "lio";
  o.health_period_s = 0.0;
  o.publish_progress = false;
  o.quiet = true;
  auto node = std::make_unique<Node>(lcm, o);
  ::unsetenv("LIVO_LATENCY_TRACE");
  node->subscribe<imu_t>("IMU", [&](const imu_t& m) {
    odometry_t out{};
    out.utime = m.utime;
    node->publish("ODOMETRY", out);
  });
  {
    record::ArrivalLog log(lcm, arrivals_path);  // every channel but PROGRESS
    point_cloud_t cloud{};
    cloud.utime = 1'000'000;
    cloud.frame = "L";
    cloud.sweep_duration = 0.1f;
    lcm.publish("LIDAR", &cloud);
    imu_t imu{};
    imu.utime = 1'100'000;
    lcm.publish("IMU", &imu);
    const uint8_t progress[3] = {1, 2, 3};  // not timed
    lcm.publish("PROGRESS", progress, sizeof progress);
    drain(lcm);
    log.flush();
    EXPECT_EQ(log.written(), 3);
  }
  node.reset();  // closes the trace
  const std::vector<Arrival> a = readArrivals(arrivals_path);
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a[0].channel, "LIDAR");
  EXPECT_EQ(a[0].type, "livo.point_cloud_t");
  EXPECT_EQ(a[0].utime, 1'000'000);
  EXPECT_EQ(a[0].end_utime, 1'100'000);  // utime + sweep_duration
  EXPECT_EQ(a[1].channel, "IMU");
  EXPECT_EQ(a[1].end_utime, 1'100'000);
  EXPECT_EQ(a[2].channel, "ODOMETRY");
  EXPECT_GT(a[0].arrival_us, 1'600'000'000'000'000);  // wall clock
  const std::vector<PublishTrace> t = readPublishTraces(trace_path, "lio");
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t[0].channel, "ODOMETRY");
  EXPECT_EQ(t[0].utime, 1'100'000);
  EXPECT_EQ(t[0].trigger_channel, "IMU");
  EXPECT_EQ(t[0].trigger_utime, 1'100'000);
  EXPECT_EQ(t[0].trigger_recv_us, a[1].arrival_us);  // memq: one receive for all
  EXPECT_LE(t[0].trigger_recv_us, t[0].start_us);
  EXPECT_LE(t[0].start_us, t[0].publish_us);
  EXPECT_LE(t[0].publish_us, a[2].arrival_us);
}

}  // namespace
}  // namespace livo::report
