// The livo-lio-graph node on LCM's in-process memq:// provider, and LOOP_CORRECTION as livo-lio
// and livo-lio-graph take it (livo/loop_correction_message.hpp): a correction of the current epoch
// newer than the adopted one is applied when it arrives and the later outputs say so; one of
// another epoch, an older or repeated one and a malformed one are refused; an IMU gap resets the
// odometry into a new epoch, after which the old epoch's corrections are refused.
#include <gtest/gtest.h>

#include <algorithm>

#include "bus_messages.hpp"
#include "livo/keyframe_t.hpp"
#include "livo/lio_graph/lio_graph_node.hpp"
#include "livo/loop_correction_message.hpp"
#include "livo/messages.hpp"
#include "livo/odometry_t.hpp"
#include "livo/registered_scan_t.hpp"
#include "synthetic_messages.hpp"
#include "synthetic_world.hpp"

using namespace livo;
using namespace livo::lio_graph;
namespace synth = livo::lio::synth;

namespace {

const char* kConfig = R"(
rig:
  channels: {imu: IMU, lidar: LIDAR, wheel: WHEEL, ground_truth: GROUND_TRUTH}
  imu: {rate_hz: 200, gyro_noise_density: 1.7e-4, gyro_random_walk: 1.9e-5, accel_noise_density: 2.0e-3, accel_random_walk: 3.0e-3, gravity: 9.81}
  lidar: {model: VLP-16, rate_hz: 10, min_range: 0.5, max_range: 100.0, range_noise_std: 0.01, dropout_probability: 0.02,
          T_I_L: {translation: [0.05, 0.0, 0.1], rpy_deg: [0.0, 0.0, 90.0]}}
)";

constexpr int64_t kBase = 1'000'000'000;  // the synthetic sequence's first stamp

using livo_test::encode;
using livo_test::Message;

struct Outputs {
  std::vector<odometry_t> odometry;
  std::vector<registered_scan_t> scans;
  std::vector<keyframe_t> keyframes;
  int64_t rejected_corrections = 0;
  int64_t resets = 0;
  OdometryFrame frame;
};

Outputs runNode(std::vector<Message> messages) {
  livo_test::sortByArrival(&messages);
  lcm::LCM lcm("memq://");
  EXPECT_TRUE(lcm.good());
  NodeOptions node_options;
  node_options.name = "lio_graph";
  node_options.health_period_s = 0.0;
  node_options.quiet = true;
  LioGraphNode node(lcm, node_options, readLioGraphNodeOptions(Config::fromString(kConfig)));
  Node observer(lcm, NodeOptions{"observer", "PROGRESS_OBS", "HEALTH_OBS", 0.0, false, true, {}});
  Outputs out;
  observer.subscribe<odometry_t>("ODOMETRY", [&](const odometry_t& m) { out.odometry.push_back(m); });
  observer.subscribe<registered_scan_t>("REGISTERED_SCAN", [&](const registered_scan_t& m) { out.scans.push_back(m); });
  observer.subscribe<keyframe_t>("KEYFRAME", [&](const keyframe_t& m) { out.keyframes.push_back(m); });
  livo_test::publishAll(lcm, messages);
  for (const auto& c : node.node().channelStats())
    if (c.channel == "LOOP_CORRECTION") out.rejected_corrections = c.rejected + c.decode_failures;
  out.resets = node.resets();
  out.frame = node.frame();
  return out;
}

/// The room walk (realistic IMU, LiDAR rotated on the body), each message keyed by its arrival
/// in sensor order (a sweep arrives at its end, an IMU sample at its stamp). Without the IMU in
/// `imu_gap` (trajectory seconds), if given.
std::vector<Message> syntheticRun(double duration, double gap_from = -1.0, double gap_to = -1.0) {
  synth::SequenceSpec spec;
  spec.duration = duration;
  spec.imu_error = synth::realisticImu();
  spec.lidar.range_noise_std = 0.01;
  spec.T_I_L = se3::fromRotationTranslation(so3::Exp(Vec3(0.0, 0.0, M_PI / 2)), Vec3(0.05, 0.0, 0.1));
  const synth::SyntheticSequence seq(spec);
  std::vector<Message> msgs;
  for (const auto& s : seq.imu()) {
    const double t = static_cast<double>(s.utime - kBase) * 1e-6;
    if (t > gap_from && t < gap_to) continue;
    msgs.push_back(encode(s.utime, "IMU", synth::imuMessage(s)));
  }
  for (int k = 0; k < seq.numScans(); ++k)
    msgs.push_back(encode(seq.scanEndUtime(k), "LIDAR", synth::cloudMessage(seq.scan(k))));
  return msgs;
}

loop_correction_t correction(int64_t id, int64_t previous_id, int32_t epoch, const Pose3& T_Ck_Cj,
                             const Pose3& T_Ck_O) {
  loop_correction_t lc{};
  lc.utime = kBase;
  lc.correction_id = id;
  lc.previous_correction_id = previous_id;
  lc.epoch = epoch;
  poseTo(T_Ck_Cj, lc.correction_position, lc.correction_orientation);
  poseTo(T_Ck_O, lc.odometry_to_corrected_position, lc.odometry_to_corrected_orientation);
  return lc;
}

Pose3 poseOf(const odometry_t& o) { return poseFrom(o.position, o.orientation); }

}  // namespace

TEST(LoopCorrectionMessage, ParsesAndRefusesAsLivoLio) {
  const Pose3 T = se3::fromRotationTranslation(so3::Exp(Vec3(0.0, 0.0, 0.1)), Vec3(1.0, 2.0, 0.0));
  loop_correction_t m = correction(2, 1, 0, T, T);
  m.num_keyframes = 2;
  m.keyframe_id = {9, 4};
  m.position = {{1.0, 0.0, 0.0}, {2.0, 0.0, 0.0}};
  m.orientation = {{1.0, 0.0, 0.0, 0.0}, {1.0, 0.0, 0.0, 0.0}};
  LoopCorrection c;
  std::vector<KeyframePose> poses;
  std::string why;
  ASSERT_TRUE(fromMessage(m, &c, &poses, &why)) << why;
  EXPECT_EQ(c.id, 2);
  EXPECT_EQ(c.previous_id, 1);
  EXPECT_TRUE(c.T_Ck_O.isApprox(T, 1e-12));
  EXPECT_TRUE(c.T_Ck_Cj.isApprox(T, 1e-12));
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(poses[0].id, 4);  // in id order
  EXPECT_LT((poses[0].pose.translation() - Vec3(2.0, 0.0, 0.0)).norm(), 1e-12);

  loop_correction_t bad = m;
  bad.previous_correction_id = 2;
  EXPECT_FALSE(fromMessage(bad, &c, &poses, &why));
  EXPECT_EQ(why, "loop correction 2: previous_correction_id 2 is not before it");
  bad = m;
  bad.correction_id = 0;
  bad.previous_correction_id = 0;
  EXPECT_FALSE(fromMessage(bad, &c, &poses, &why));

  OdometryFrame frame;
  frame.epoch = 1;
  frame.correction_id = 1;
  m.epoch = 0;
  EXPECT_EQ(adoptionRefusal(m, frame), "loop correction 2 is for odometry epoch 0, the filter is in epoch 1: ignored");
  m.epoch = 1;
  EXPECT_EQ(adoptionRefusal(m, frame), "");
  frame.correction_id = 2;
  EXPECT_EQ(adoptionRefusal(m, frame), "loop correction 2 is not after the adopted one (2): ignored");
  frame.correction_id = 5;
  EXPECT_EQ(adoptionRefusal(m, frame), "loop correction 2 is not after the adopted one (5): ignored");
}

// Corrections arriving between sweeps: one for another epoch, the first of epoch 0 (adopted), the
// same again, a malformed one, then correction 3 after a missed 2 (adopted through T_C3_O). Every
// output says the frame it is in, and is the uncorrected run's moved by that frame's T_C_O.
TEST(LioGraphNode, AdoptsLoopCorrectionsOfItsEpochInOrder) {
  const std::vector<Message> plain = syntheticRun(3.0);
  const Pose3 T1 = se3::fromRotationTranslation(so3::Exp(Vec3(0.0, 0.0, 0.05)), Vec3(0.3, -0.2, 0.0));
  const Pose3 T3 = se3::fromRotationTranslation(so3::Exp(Vec3(0.005, 0.0, -0.04)), Vec3(-0.2, 0.4, 0.02));
  const int64_t first = kBase + 1'400'000, third = kBase + 2'200'000;
  std::vector<Message> msgs = plain;
  msgs.push_back(encode(first, "LOOP_CORRECTION", correction(1, 0, 1, T1, T1)));            // another epoch
  msgs.push_back(encode(first + 1, "LOOP_CORRECTION", correction(1, 0, 0, T1, T1)));        // adopted
  msgs.push_back(encode(first + 300'000, "LOOP_CORRECTION", correction(1, 0, 0, T1, T1)));  // repeated
  msgs.push_back(encode(first + 300'001, "LOOP_CORRECTION", correction(2, 2, 0, T1, T1)));  // malformed
  // the transform from correction 2 (never received) is useless here: T_C3_O * T_C1_O^-1 is taken
  msgs.push_back(encode(third, "LOOP_CORRECTION",
                        correction(3, 2, 0, se3::fromRotationTranslation(Mat3::Identity(), Vec3(5.0, 5.0, 5.0)), T3)));

  const Outputs out = runNode(msgs);
  const Outputs ref = runNode(plain);
  EXPECT_EQ(out.rejected_corrections, 3);
  EXPECT_EQ(out.frame.epoch, 0);
  EXPECT_EQ(out.frame.correction_id, 3);
  ASSERT_EQ(out.odometry.size(), ref.odometry.size());
  ASSERT_GT(out.odometry.size(), 15u);
  ASSERT_EQ(out.scans.size(), out.odometry.size());
  int seen[4] = {0, 0, 0, 0};
  for (size_t i = 0; i < out.odometry.size(); ++i) {
    const odometry_t& o = out.odometry[i];
    ASSERT_EQ(o.utime, ref.odometry[i].utime);
    EXPECT_EQ(o.epoch, 0);
    // a sweep is processed once the IMU reached its end: before a correction arriving later
    const int64_t expected = o.utime <= first ? 0 : o.utime <= third ? 1 : 3;
    EXPECT_EQ(o.correction_id, expected) << o.utime;
    ++seen[o.correction_id];
    EXPECT_EQ(out.scans[i].epoch, o.epoch);
    EXPECT_EQ(out.scans[i].correction_id, o.correction_id);
    const Pose3 T = o.correction_id == 0 ? Pose3::Identity() : o.correction_id == 1 ? T1 : T3;
    const Pose3 moved = T * poseOf(ref.odometry[i]);
    EXPECT_LT((poseOf(o).translation() - moved.translation()).norm(), 0.05) << o.utime;
    EXPECT_LT(so3::Log(Mat3(moved.linear().transpose() * poseOf(o).linear())).norm(), 0.01) << o.utime;
  }
  EXPECT_GT(seen[0], 0);
  EXPECT_GT(seen[1], 0);
  EXPECT_GT(seen[3], 0);
  for (const keyframe_t& k : out.keyframes) {
    EXPECT_EQ(k.epoch, 0);
    EXPECT_TRUE(k.correction_id == 0 || k.correction_id == 1 || k.correction_id == 3) << k.correction_id;
  }
}

// An IMU gap resets the odometry into epoch 1 (warned like livo-lio's reset); a correction made
// for epoch 0 that arrives afterwards is refused, and the new epoch's outputs stay uncorrected.
TEST(LioGraphNode, ImuGapStartsANewEpochAndRefusesTheOldOnesCorrections) {
  std::vector<Message> msgs = syntheticRun(4.5, 2.0, 2.7);
  const Pose3 T = se3::fromRotationTranslation(so3::Exp(Vec3(0.0, 0.0, 0.02)), Vec3(0.1, 0.0, 0.0));
  msgs.push_back(encode(kBase + 1'500'000, "LOOP_CORRECTION", correction(1, 0, 0, T, T)));
  msgs.push_back(encode(kBase + 3'000'000, "LOOP_CORRECTION", correction(2, 1, 0, T, T)));
  const Outputs out = runNode(msgs);
  EXPECT_EQ(out.resets, 1);
  EXPECT_EQ(out.rejected_corrections, 1);
  EXPECT_EQ(out.frame.epoch, 1);
  EXPECT_EQ(out.frame.correction_id, 0);
  int epoch0_corrected = 0, epoch1 = 0;
  for (const odometry_t& o : out.odometry) {
    EXPECT_TRUE(allFinite(o.position, 3));
    if (o.epoch == 0) {
      epoch0_corrected += o.correction_id == 1;
      EXPECT_LE(o.correction_id, 1);
    } else {
      EXPECT_EQ(o.epoch, 1);
      EXPECT_EQ(o.correction_id, 0);
      ++epoch1;
    }
  }
  EXPECT_GT(epoch0_corrected, 0);
  EXPECT_GT(epoch1, 0);
}

// The scan-to-map plane test's keys (livo-lio's test: neighbours within max_neighbour_distance, a
// plane thinner than max_plane_distance, the collinearity ratio min_planarity) and the surface
// features' voxel are read, and a value out of range is refused naming its own key.
TEST(LioGraphConfig, ReadsThePlaneTestAndRefusesOutOfRangeValuesNamingTheKey) {
  const std::string rig = kConfig;
  const LioGraphNodeOptions defaults = readLioGraphNodeOptions(Config::fromString(rig));
  EXPECT_DOUBLE_EQ(defaults.core.matching.max_neighbour_distance, 1.5);
  EXPECT_DOUBLE_EQ(defaults.core.matching.max_plane_distance, 0.03);
  EXPECT_DOUBLE_EQ(defaults.core.matching.min_planarity, 0.02);
  EXPECT_DOUBLE_EQ(defaults.core.features.surface_voxel, 0.2);
  const LioGraphNodeOptions lio_sam = readLioGraphNodeOptions(Config::fromString(
      rig +
      "lio_graph: {max_neighbour_distance: 1.0, max_plane_distance: 0.2, min_planarity: 0, surface_voxel: 0.4}\n"));
  EXPECT_DOUBLE_EQ(lio_sam.core.matching.max_neighbour_distance, 1.0);
  EXPECT_DOUBLE_EQ(lio_sam.core.matching.max_plane_distance, 0.2);
  EXPECT_DOUBLE_EQ(lio_sam.core.matching.min_planarity, 0.0);
  EXPECT_DOUBLE_EQ(lio_sam.core.features.surface_voxel, 0.4);

  const auto refusal = [&](const std::string& section) {
    try {
      readLioGraphNodeOptions(Config::fromString(rig + "lio_graph: {" + section + "}\n"));
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"max_neighbour_distance: 0", "lio_graph.max_neighbour_distance"},
      {"max_plane_distance: -0.01", "lio_graph.max_plane_distance"},
      {"min_planarity: 1.0", "lio_graph.min_planarity"},
      {"min_planarity: -0.1", "lio_graph.min_planarity"},
      {"surface_voxel: 0", "lio_graph.surface_voxel"},
      {"max_stored_keyframes: 0", "lio_graph.max_stored_keyframes"},
      {"keyframe_distance: 0", "lio_graph.keyframe_distance"},
      {"wheel_scale_std: 0.3", "lio_graph.wheel_scale_std"},
      {"lidar_point_sigma: 0", "lio_graph.lidar_point_sigma"},
      {"plane_threshold_per_metre: -1", "lio_graph.plane_threshold_per_metre"},
      {"visual_sigma_rotation_deg: 0", "lio_graph.visual_sigma_rotation_deg"},
      {"min_plane_distance: 0.1", "min_plane_distance"},  // an unknown key, named
  };
  for (const auto& [section, key] : bad) {
    const std::string why = refusal(section);
    EXPECT_NE(why, "accepted") << section;
    EXPECT_NE(why.find(key), std::string::npos) << section << " -> " << why;
  }
}
