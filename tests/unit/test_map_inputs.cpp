// The map builders' inputs (livo/map_inputs.hpp): registered-scan views, keyframe and loop
// correction checks, shared by livo-colour and livo-octomap.
#include <gtest/gtest.h>

#include <cmath>

#include "livo/keyframe_t.hpp"
#include "livo/loop_correction_t.hpp"
#include "livo/map_inputs.hpp"
#include "livo/message_checks.hpp"
#include "livo/messages.hpp"
#include "livo/node.hpp"
#include "livo/registered_scan_t.hpp"
#include "loop_correction_fixtures.hpp"

using namespace livo;

namespace {
Pose3 pose(double x, double yaw) {
  Pose3 T = Pose3::Identity();
  T.linear() = so3::Exp(Vec3(0.0, 0.0, yaw));
  T.translation() = Vec3(x, 0.5, -1.0);
  return T;
}

loop_correction_t correction(const std::vector<std::pair<int64_t, Pose3>>& poses) {
  loop_correction_t m{};
  m.correction_orientation[0] = 1.0;
  livo_test::setKeyframePoses(poses, &m);
  return m;
}
}  // namespace

TEST(MapInputs, RegisteredScanViewPointsIntoTheMessage) {
  registered_scan_t m{};
  m.utime = 2000000;
  poseTo(pose(3.0, 0.4), m.position, m.orientation);
  m.cloud.utime = 1900000;
  m.cloud.frame = "W";
  m.cloud.num_points = 2;
  m.cloud.x = {1, 2};
  m.cloud.y = {3, 4};
  m.cloud.z = {5, 6};
  m.cloud.time_offset = {0.f, 0.05f};
  RegisteredScanView v;
  ASSERT_EQ(viewRegisteredScan(m, &v), "");
  EXPECT_EQ(v.utime, 2000000);
  EXPECT_EQ(v.cloud_utime, 1900000);
  EXPECT_EQ(v.num_points, 2);
  EXPECT_EQ(v.x, m.cloud.x.data());
  EXPECT_EQ(v.time_offset, m.cloud.time_offset.data());
  EXPECT_TRUE(v.T_W_I.isApprox(pose(3.0, 0.4), 1e-12));
  m.cloud.frame = "I";
  EXPECT_EQ(viewRegisteredScan(m, &v), "cloud frame is 'I', expected W");
}

TEST(MapInputs, PoseAndKeyframeProblems) {
  double p[3] = {1, 2, 3}, q[4] = {1, 0, 0, 0};
  EXPECT_EQ(poseProblem(p, q), "");
  q[0] = 0.0;  // poseFrom() would silently make this the identity
  EXPECT_EQ(poseProblem(p, q), "orientation is not a unit quaternion");
  q[0] = 1.0;
  p[2] = NAN;
  EXPECT_EQ(poseProblem(p, q), "pose is not finite");

  keyframe_t k{};
  k.orientation[0] = 1.0;
  k.cloud.frame = "I";
  k.cloud.num_points = 1;
  k.cloud.x = {1}, k.cloud.y = {2}, k.cloud.z = {3};
  EXPECT_EQ(keyframeProblem(k), "");
  k.cloud.frame = "W";
  EXPECT_EQ(keyframeProblem(k), "cloud frame is 'W', expected I");
  k.cloud.frame = "I";
  k.cloud.z.clear();
  EXPECT_EQ(keyframeProblem(k), "cloud arrays disagree with num_points");
  k.cloud.z = {3};
  k.orientation[0] = NAN;
  EXPECT_EQ(keyframeProblem(k), "pose is not finite");
}

TEST(MapInputs, CorrectedKeyframePoses) {
  std::map<int64_t, Pose3> poses;
  ASSERT_EQ(correctedKeyframePoses(correction({{4, pose(1.0, 0.1)}, {9, pose(2.0, -0.3)}}), &poses), "");
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_TRUE(poses.at(4).isApprox(pose(1.0, 0.1), 1e-12));
  EXPECT_TRUE(poses.at(9).isApprox(pose(2.0, -0.3), 1e-12));

  loop_correction_t bad = correction({{4, pose(1.0, 0.1)}, {9, pose(2.0, -0.3)}});
  bad.orientation[1][2] = INFINITY;
  EXPECT_EQ(correctedKeyframePoses(bad, &poses), "corrected pose is not finite");
  EXPECT_EQ(poses.size(), 2u);  // untouched on failure
  bad = correction({{4, pose(1.0, 0.1)}});
  bad.num_keyframes = 2;
  EXPECT_EQ(correctedKeyframePoses(bad, &poses), "arrays disagree with num_keyframes");
  bad = correction({{4, pose(1.0, 0.1)}});
  bad.position[0].pop_back();
  EXPECT_EQ(correctedKeyframePoses(bad, &poses), "malformed corrected pose");
  EXPECT_EQ(correctedKeyframePoses(correction({}), &poses), "");
  EXPECT_TRUE(poses.empty());
}

// The map builders' shared intake (takeKeyframePose / takeMapCorrection): a refusal is counted on
// the node's channel, a keyframe's placement (which may start a new epoch) is asked only for a
// sound message, and a correction the map does not move to is no refusal.
TEST(MapInputs, TakeKeyframePoseAndMapCorrectionRefuseOnTheNode) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  Node node(lcm, NodeOptions{"map_builder", "PROGRESS_MB", "HEALTH_MB", 0.0, false, true, {}});
  node.subscribe<keyframe_t>("KEYFRAME", [](const keyframe_t&) {});
  node.subscribe<loop_correction_t>("LOOP_CORRECTION", [](const loop_correction_t&) {});
  const auto rejected = [&](const std::string& channel) {
    for (const channel_stats_t& s : node.channelStats())
      if (s.channel == channel) return s.rejected;
    return int64_t{-1};
  };

  keyframe_t k{};
  poseTo(pose(2.0, 0.3), k.position, k.orientation);
  k.cloud.frame = "I";
  int placements = 0;
  MapFrame::Placed shifted;
  shifted.placement = MapFrame::Placement::kUse;
  shifted.to_map = pose(1.0, 0.0);
  const auto place = [&] {
    ++placements;
    return shifted;
  };
  Pose3 T;
  ASSERT_TRUE(takeKeyframePose(node, "KEYFRAME", k, true, place, &T));
  EXPECT_LT((T.matrix() - (pose(1.0, 0.0) * pose(2.0, 0.3)).matrix()).norm(), 1e-12);
  EXPECT_EQ(placements, 1);

  keyframe_t bad = k;
  bad.position[1] = std::nan("");
  EXPECT_FALSE(takeKeyframePose(node, "KEYFRAME", bad, false, place, &T));
  EXPECT_EQ(placements, 1);  // not placed: a bad message must not start an epoch
  EXPECT_EQ(rejected("KEYFRAME"), 1);

  keyframe_t torn = k;  // the cloud's arrays disagree with num_points: only a builder of clouds refuses
  torn.cloud.num_points = 3;
  EXPECT_TRUE(takeKeyframePose(node, "KEYFRAME", torn, false, place, &T));
  EXPECT_FALSE(takeKeyframePose(node, "KEYFRAME", torn, true, place, &T));
  EXPECT_EQ(rejected("KEYFRAME"), 2);

  shifted.placement = MapFrame::Placement::kOldEpoch;
  shifted.why = "of another epoch";
  EXPECT_FALSE(takeKeyframePose(node, "KEYFRAME", k, true, place, &T));
  EXPECT_EQ(rejected("KEYFRAME"), 3);

  MapFrame frame;
  MapCorrection c;
  loop_correction_t torn_correction = correction({{1, pose(0.0, 0.0)}});
  torn_correction.num_keyframes = 2;
  EXPECT_FALSE(takeMapCorrection(node, "LOOP_CORRECTION", torn_correction, &frame, &c));
  EXPECT_FALSE(c.problem.empty());
  EXPECT_EQ(rejected("LOOP_CORRECTION"), 1);
}
