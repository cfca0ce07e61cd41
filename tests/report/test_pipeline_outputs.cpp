// Reading a run's outputs, the loop-corrected trajectory against known corrections, timing.json.
#include <gtest/gtest.h>

#include <lcm/lcm-cpp.hpp>

#include "evaluate/lcm_log_writer.hpp"
#include "livo/keyframe_t.hpp"
#include "livo/messages.hpp"
#include "livo/odometry_t.hpp"
#include "livo/report/pipeline_outputs.hpp"
#include "livo/report/run_report.hpp"
#include "temp_path.hpp"

using namespace livo;
using namespace livo::report;

namespace {

Pose3 poseAt(int i) {
  Vec6 xi;
  xi << 0.0, 0.0, 0.05 * i, 1.0 * i, 0.2 * i, 0.0;
  return se3::boxplus(Pose3::Identity(), xi);
}

// 20 scans, keyframes at scans 0, 5, 10, 15; a loop correction for keyframes 0..2.
// With adopted_tail, that many more scans follow the correction, published by a LIO that adopted
// it (already corrected by correction_kf2), the first of them a keyframe.
// Without keyframes, no KEYFRAME is written (a run that did not record them).
std::string makeOutputs(const Pose3& correction_kf1, const Pose3& correction_kf2, bool with_loop, bool with_nan,
                        int adopted_tail = 0, bool with_keyframes = true) {
  const std::string path = livo_test::tempPath("outputs_") + std::to_string(with_loop) + std::to_string(with_nan) +
                           std::to_string(adopted_tail) + std::to_string(with_keyframes) + ".lcmlog";
  lcm::LogFile log(path, "w");
  for (int i = 0; i < 20; ++i) {
    const int64_t t = 1000000 + i * 100000;
    odometry_t o{};
    o.utime = t;
    poseTo(poseAt(i), o.position, o.orientation);
    if (with_nan && i == 7) o.position[1] = std::nan("");
    fixtures::writeMessage(log, "ODOMETRY", t, o);
    if (with_keyframes && i % 5 == 0) {
      keyframe_t k{};
      k.id = i / 5;
      k.utime = t;
      poseTo(poseAt(i), k.position, k.orientation);
      k.cloud.frame = "I";
      fixtures::writeMessage(log, "KEYFRAME", t, k);
    }
  }
  if (with_loop) {
    loop_correction_t lc{};
    lc.utime = 2000000;
    lc.num_keyframes = 3;
    const Pose3 corr[3] = {Pose3::Identity(), correction_kf1, correction_kf2};
    for (int k = 0; k < 3; ++k) {
      lc.keyframe_id.push_back(k);
      std::array<double, 3> p;
      std::array<double, 4> q;
      poseTo(corr[k] * poseAt(5 * k), p.data(), q.data());
      lc.position.push_back({p[0], p[1], p[2]});
      lc.orientation.push_back({q[0], q[1], q[2], q[3]});
    }
    lc.correction_id = 1;
    poseTo(correction_kf2, lc.correction_position, lc.correction_orientation);
    poseTo(correction_kf2, lc.odometry_to_corrected_position, lc.odometry_to_corrected_orientation);
    fixtures::writeMessage(log, "LOOP_CORRECTION", 2000000, lc);
    for (int i = 20; i < 20 + adopted_tail; ++i) {
      const int64_t t = 1000000 + i * 100000;
      odometry_t o{};
      o.utime = t;
      o.correction_id = 1;  // lio adopted correction 1
      poseTo(correction_kf2 * poseAt(i), o.position, o.orientation);
      fixtures::writeMessage(log, "ODOMETRY", t, o);
      if (with_keyframes && i == 20) {
        keyframe_t k{};
        k.id = 4;
        k.utime = t;
        k.correction_id = 1;
        poseTo(correction_kf2 * poseAt(i), k.position, k.orientation);
        k.cloud.frame = "I";
        fixtures::writeMessage(log, "KEYFRAME", t, k);
      }
    }
  }
  health_t h{};
  h.node = "lio";
  h.peak_rss_mb = 42.0;
  channel_stats_t imu{}, lidar{};
  imu.channel = "IMU";
  imu.messages = 400;
  imu.median_ms = 0.01;
  imu.p90_ms = 0.02;
  imu.max_ms = 0.1;
  lidar.channel = "LIDAR";
  lidar.messages = 20;
  lidar.median_ms = 5.0;
  lidar.p90_ms = 7.0;
  lidar.max_ms = 9.0;
  lidar.rejected = 1;
  h.channels = {imu, lidar};
  h.num_channels = 2;
  fixtures::writeMessage(log, "HEALTH", 3000000, h);
  return path;
}

}  // namespace

TEST(PipelineOutputs, NoLoopMeansTrajectoryEqualsOdometry) {
  const PipelineOutputs out = readPipelineOutputs(makeOutputs(Pose3::Identity(), Pose3::Identity(), false, true));
  EXPECT_EQ(out.odometry.size(), 19u);  // the NaN pose is dropped and counted
  EXPECT_EQ(out.non_finite, 1);
  EXPECT_EQ(out.keyframes.size(), 4u);
  EXPECT_TRUE(out.last_loop.empty());
  const Trajectory t = loopCorrectedTrajectory(out);
  ASSERT_EQ(t.size(), out.odometry.size());
  for (size_t i = 0; i < t.size(); ++i) EXPECT_TRUE(t[i].pose.isApprox(out.odometry[i].pose, 1e-12));
}

TEST(PipelineOutputs, LoopCorrectionMovesEachSpanByItsKeyframe) {
  Vec6 a, b;
  a << 0.0, 0.0, 0.02, 0.3, -0.1, 0.0;
  b << 0.0, 0.0, -0.03, -0.5, 0.4, 0.1;
  const Pose3 c1 = se3::Exp(a), c2 = se3::Exp(b);
  const PipelineOutputs out = readPipelineOutputs(makeOutputs(c1, c2, true, false));
  ASSERT_EQ(out.last_loop.size(), 1u);
  const Trajectory t = loopCorrectedTrajectory(out);
  ASSERT_EQ(t.size(), 20u);
  for (int i = 0; i < 20; ++i) {
    // scans 0-4 follow keyframe 0 (no correction), 5-9 keyframe 1 (c1), 10-19 keyframe 2 and the
    // newer keyframe 3, which the correction does not list: the overall correction c2
    const Pose3 c = i < 5 ? Pose3::Identity() : i < 10 ? c1 : c2;
    const Pose3 expected = c * poseAt(i);
    EXPECT_NEAR((t[i].pose.matrix() - expected.matrix()).norm(), 0.0, 1e-9) << i;
  }
}

// A run that recorded LOOP_CORRECTION but no KEYFRAME: no pose can be tied to a keyframe's
// correction, so trajectory.tum is the odometry as published (each pose in the correction lio had
// adopted: the online trajectory) and a warning says so. Before, every pose was moved by the last
// correction's overall transform, which looked final and was worse than the odometry.
TEST(PipelineOutputs, CorrectionsWithoutKeyframesLeaveTheOdometryAndWarn) {
  Vec6 a, b;
  a << 0.0, 0.0, 0.02, 0.3, -0.1, 0.0;
  b << 0.0, 0.0, -0.03, -0.5, 0.4, 0.1;
  const PipelineOutputs out = readPipelineOutputs(makeOutputs(se3::Exp(a), se3::Exp(b), true, false, 6, false));
  ASSERT_TRUE(out.keyframes.empty());
  ASSERT_EQ(out.last_loop.size(), 1u);
  std::vector<std::string> warnings;
  const Trajectory t = loopCorrectedTrajectory(out, &warnings);
  ASSERT_EQ(t.size(), out.odometry.size());
  for (size_t i = 0; i < t.size(); ++i) EXPECT_TRUE(t[i].pose.isApprox(out.odometry[i].pose, 1e-12)) << i;
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("no KEYFRAME"), std::string::npos) << warnings[0];
  // with the keyframes the same log gives the corrected trajectory and no warning
  warnings.clear();
  const PipelineOutputs with = readPipelineOutputs(makeOutputs(se3::Exp(a), se3::Exp(b), true, false, 6, true));
  loopCorrectedTrajectory(with, &warnings);
  EXPECT_TRUE(warnings.empty());
}

// livo-lio adopts a loop correction: what it publishes after it is already corrected and is not
// moved again, while what came before still is.
TEST(PipelineOutputs, OdometryAfterAnAdoptedCorrectionIsKept) {
  Vec6 a, b;
  a << 0.0, 0.0, 0.02, 0.3, -0.1, 0.0;
  b << 0.0, 0.0, -0.03, -0.5, 0.4, 0.1;
  const Pose3 c1 = se3::Exp(a), c2 = se3::Exp(b);
  const PipelineOutputs out = readPipelineOutputs(makeOutputs(c1, c2, true, false, 6));
  const Trajectory t = loopCorrectedTrajectory(out);
  ASSERT_EQ(t.size(), 26u);
  for (int i = 0; i < 26; ++i) {
    const Pose3 expected = (i < 5 ? Pose3::Identity() : i < 10 ? c1 : c2) * poseAt(i);
    EXPECT_NEAR((t[i].pose.matrix() - expected.matrix()).norm(), 0.0, 1e-9) << i;
  }
}

// Real-time order: odometry lio published before adopting correction 1 is logged after it (still
// corrected, once), odometry published after adoption is kept; then a reset to epoch 1 (listed
// with lio's reason; its odometry is in its own frame and not corrected).
TEST(PipelineOutputs, ExplicitCorrectionIdsAndResets) {
  Vec6 a;
  a << 0.0, 0.0, 0.02, 0.3, -0.1, 0.0;
  const Pose3 c = se3::Exp(a);
  const std::string path = livo_test::tempPath("outputs_realtime") + ".lcmlog";
  {
    lcm::LogFile log(path, "w");
    auto odometry = [&](int i, int32_t epoch, int64_t correction_id, const Pose3& pose) {
      odometry_t o{};
      o.utime = 1000000 + i * 100000;
      o.epoch = epoch;
      o.correction_id = correction_id;
      poseTo(pose, o.position, o.orientation);
      fixtures::writeMessage(log, "ODOMETRY", o.utime, o);
    };
    keyframe_t k{};
    k.utime = 1000000;
    poseTo(poseAt(0), k.position, k.orientation);
    k.cloud.frame = "I";
    fixtures::writeMessage(log, "KEYFRAME", k.utime, k);
    for (int i = 0; i < 10; ++i) odometry(i, 0, 0, poseAt(i));
    loop_correction_t lc{};
    lc.utime = 1900000;
    lc.correction_id = 1;
    lc.num_keyframes = 1;
    lc.keyframe_id = {0};
    std::array<double, 3> p;
    std::array<double, 4> q;
    poseTo(c * poseAt(0), p.data(), q.data());
    lc.position = {{p[0], p[1], p[2]}};
    lc.orientation = {{q[0], q[1], q[2], q[3]}};
    poseTo(c, lc.correction_position, lc.correction_orientation);
    poseTo(c, lc.odometry_to_corrected_position, lc.odometry_to_corrected_orientation);
    fixtures::writeMessage(log, "LOOP_CORRECTION", lc.utime, lc);
    odometry(10, 0, 0, poseAt(10));      // published before lio adopted correction 1
    odometry(11, 0, 1, c * poseAt(11));  // after
    health_t h{};
    h.node = "lio";
    h.level = health_t::LEVEL_WARN;
    h.message = "odometry reset to epoch 1: IMU time jumped back by 5.000000 s: re-initialising";
    fixtures::writeMessage(log, "HEALTH", 2150000, h);
    odometry(12, 1, 0, poseAt(1));
  }
  const PipelineOutputs out = readPipelineOutputs(path);
  const Trajectory t = loopCorrectedTrajectory(out);
  ASSERT_EQ(t.size(), 13u);
  for (int i = 0; i < 12; ++i) EXPECT_NEAR((t[i].pose.matrix() - (c * poseAt(i)).matrix()).norm(), 0.0, 1e-9) << i;
  EXPECT_NEAR((t[12].pose.matrix() - poseAt(1).matrix()).norm(), 0.0, 1e-12);  // epoch 1: no loop
  ASSERT_EQ(out.resets.size(), 1u);
  EXPECT_EQ(out.resets[0].epoch, 1);
  EXPECT_DOUBLE_EQ(out.resets[0].stamp, 2.2);
  EXPECT_EQ(out.resets[0].reason, "IMU time jumped back by 5.000000 s: re-initialising");
  EXPECT_NE(resetsJson(out.resets).find("\"epoch\": 1"), std::string::npos);
}

TEST(PipelineOutputs, TimingJsonHeadlinesTheBusiestInput) {
  const PipelineOutputs out = readPipelineOutputs(makeOutputs(Pose3::Identity(), Pose3::Identity(), false, false));
  const nlohmann::json j = timingJson(out.final_health);
  ASSERT_TRUE(j.contains("lio"));
  EXPECT_EQ(j["lio"]["busiest_channel"], "LIDAR");  // 20 x 5 ms outweighs 400 x 0.01 ms
  EXPECT_EQ(j["lio"]["messages"], 20);
  EXPECT_DOUBLE_EQ(j["lio"]["median_ms"].get<double>(), 5.0);
  EXPECT_DOUBLE_EQ(j["lio"]["p90_ms"].get<double>(), 7.0);
  EXPECT_DOUBLE_EQ(j["lio"]["max_ms"].get<double>(), 9.0);
  EXPECT_DOUBLE_EQ(j["lio"]["peak_rss_mb"].get<double>(), 42.0);
  EXPECT_EQ(j["lio"]["channels"]["LIDAR"]["rejected"], 1);
  EXPECT_EQ(j["lio"]["messages_all_channels"], 420);
  EXPECT_THROW(readPipelineOutputs("/nonexistent.lcmlog"), std::runtime_error);
}
