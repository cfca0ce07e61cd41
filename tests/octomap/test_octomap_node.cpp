// livo-octomap's node on memq://: scans in, OCTOMAP out at the publish period, files on finish,
// bad input refused; keyframes and loop corrections rebuild the tree.
#include <cmath>
#include <sstream>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>
#include <lcm/lcm-cpp.hpp>

#include "livo/keyframe_t.hpp"
#include "livo/loop_correction_t.hpp"
#include "livo/messages.hpp"
#include "livo/octomap/octomap_node.hpp"
#include "livo/octomap_t.hpp"
#include "livo/registered_scan_t.hpp"
#include "loop_correction_fixtures.hpp"
#include "temp_path.hpp"

using namespace livo;

namespace {
registered_scan_t wallScan(int64_t utime) {
  registered_scan_t s{};
  s.utime = utime;
  s.orientation[0] = 1.0;
  s.cloud.utime = utime - 100000;
  s.cloud.frame = "W";
  for (int i = -10; i <= 10; ++i)
    for (int j = -5; j <= 5; ++j) {
      s.cloud.x.push_back(2.05f);
      s.cloud.y.push_back(0.1f * i + 0.05f);
      s.cloud.z.push_back(0.1f * j + 0.05f);
    }
  s.cloud.num_points = static_cast<int32_t>(s.cloud.x.size());
  s.cloud.intensity.assign(s.cloud.x.size(), 0.f);
  s.cloud.time_offset.assign(s.cloud.x.size(), 0.f);
  s.cloud.ring.assign(s.cloud.x.size(), -1);
  return s;
}
NodeOptions quiet() {
  NodeOptions n;
  n.name = "octomap";
  n.quiet = true;
  n.health_period_s = 0;
  return n;
}

/// Every OCTOMAP message, appended to `out`.
void collect(lcm::LCM& lcm, std::vector<octomap_t>* out) {
  lcm.subscribeFunction<octomap_t, std::vector<octomap_t>*>(
      "OCTOMAP",
      [](const lcm::ReceiveBuffer*, const std::string&, const octomap_t* m, std::vector<octomap_t>* o) {
        o->push_back(*m);
      },
      out);
}

void drain(lcm::LCM& lcm) {
  while (lcm.handleTimeout(0) > 0) {
  }
}
}  // namespace

TEST(OctomapNode, PublishesTheTreeAndWritesFiles) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  livo::octomap::OctomapNodeOptions options;
  options.publish_period_s = 0.5;
  options.write_period_s = 0;
  livo::octomap::OctomapNode node(lcm, quiet(), options, SensorRig{}, livo_test::tempPath("octo"));
  std::vector<octomap_t> received;
  collect(lcm, &received);
  for (int k = 0; k < 10; ++k) {
    const registered_scan_t s = wallScan(1000000 + 100000 * k);
    lcm.publish("REGISTERED_SCAN", &s);
  }
  registered_scan_t bad = wallScan(3000000);
  bad.orientation[0] = NAN;
  lcm.publish("REGISTERED_SCAN", &bad);
  registered_scan_t empty = wallScan(3100000);
  empty.cloud.num_points = 0;
  empty.cloud.x.clear();
  lcm.publish("REGISTERED_SCAN", &empty);
  drain(lcm);
  EXPECT_EQ(node.builder().scans(), 10);
  ASSERT_EQ(received.size(), 2u);  // at 1.0 s and 1.5 s
  std::istringstream in(std::string(received.back().data.begin(), received.back().data.end()));
  ::octomap::OcTree tree(0.1);
  ASSERT_TRUE(tree.readBinary(in));
  const ::octomap::OcTreeNode* n = tree.search(2.05, 0.05, 0.05);
  ASSERT_NE(n, nullptr);
  EXPECT_TRUE(tree.isNodeOccupied(n));
  node.finish();
  ::octomap::OcTree from_file(0.1);
  EXPECT_TRUE(from_file.readBinary(node.btPath()));
  std::unique_ptr<::octomap::AbstractOcTree> ot(::octomap::AbstractOcTree::read(node.otPath()));
  EXPECT_NE(ot, nullptr);
}

namespace {
keyframe_t wallKeyframe(int64_t id, int64_t utime) {
  const registered_scan_t s = wallScan(utime);
  keyframe_t k{};
  k.id = id;
  k.utime = utime;
  k.orientation[0] = 1.0;  // identity pose: body frame = world frame
  k.cloud = s.cloud;
  k.cloud.frame = "I";
  return k;
}

// Corrections 1, 2, ... of epoch 0 with the identity as odometry_to_corrected (keyframes the
// correction does not list stay where they are).
loop_correction_t correction(int64_t utime, const std::vector<std::pair<int64_t, Pose3>>& poses) {
  static int64_t next_id = 1;
  loop_correction_t m{};
  m.utime = utime;
  m.correction_id = next_id++;
  m.correction_orientation[0] = 1.0;
  m.odometry_to_corrected_orientation[0] = 1.0;
  livo_test::setKeyframePoses(poses, &m);
  return m;
}

bool occupiedIn(const octomap_t& m, double x, double y, double z) {
  std::istringstream in(std::string(m.data.begin(), m.data.end()));
  ::octomap::OcTree tree(0.1);
  if (!tree.readBinary(in)) return false;
  const ::octomap::OcTreeNode* n = tree.search(x, y, z);
  return n && tree.isNodeOccupied(n);
}
}  // namespace

// KEYFRAME and LOOP_CORRECTION over the bus: the tree is rebuilt from the keyframes at their
// corrected poses and published at once; a malformed correction or keyframe is refused.
TEST(OctomapNode, RebuildsFromCorrectedKeyframesAndPublishes) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  livo::octomap::OctomapNodeOptions options;
  options.publish_period_s = 100.0;  // the first scan's tree, then only after corrections
  options.write_period_s = 0;
  livo::octomap::OctomapNode node(lcm, quiet(), options, SensorRig{}, livo_test::tempPath("octo_loop"));
  std::vector<octomap_t> received;
  collect(lcm, &received);
  const registered_scan_t scan = wallScan(1000000);
  lcm.publish("REGISTERED_SCAN", &scan);
  const keyframe_t kf0 = wallKeyframe(0, 1000000);
  lcm.publish("KEYFRAME", &kf0);
  keyframe_t broken = wallKeyframe(1, 1100000);
  broken.position[1] = NAN;
  lcm.publish("KEYFRAME", &broken);
  keyframe_t world_frame = wallKeyframe(2, 1100000);
  world_frame.cloud.frame = "W";
  lcm.publish("KEYFRAME", &world_frame);
  keyframe_t no_rotation = wallKeyframe(3, 1100000);
  no_rotation.orientation[0] = 0.0;  // a zero quaternion (poseFrom would make it the identity)
  lcm.publish("KEYFRAME", &no_rotation);
  drain(lcm);
  ASSERT_EQ(received.size(), 1u);
  EXPECT_TRUE(occupiedIn(received.back(), 2.05, 0.05, 0.05));
  EXPECT_EQ(node.builder().keyframes(), 1u);

  Pose3 up = Pose3::Identity();
  up.translation() = Vec3(0.0, 0.0, 2.0);
  loop_correction_t bad = correction(1200000, {{0, up}});
  bad.position[0][2] = NAN;
  lcm.publish("LOOP_CORRECTION", &bad);
  drain(lcm);
  EXPECT_EQ(node.builder().rebuilds(), 0);
  EXPECT_EQ(received.size(), 1u);

  const loop_correction_t good = correction(1200000, {{0, up}, {1, up}, {2, up}, {3, up}});  // 1-3 were refused
  lcm.publish("LOOP_CORRECTION", &good);
  drain(lcm);
  EXPECT_EQ(node.builder().rebuilds(), 1);
  ASSERT_EQ(received.size(), 2u);
  EXPECT_EQ(received.back().utime, 1200000);
  EXPECT_TRUE(occupiedIn(received.back(), 2.05, 0.05, 2.05));   // the wall 2 m up
  EXPECT_FALSE(occupiedIn(received.back(), 2.05, 0.05, 0.05));  // and no longer where it was

  lcm.publish("LOOP_CORRECTION", &good);  // the same poses again: nothing moves, nothing published
  drain(lcm);
  EXPECT_EQ(node.builder().rebuilds(), 1);
  EXPECT_EQ(received.size(), 2u);
}

namespace {
registered_scan_t wallScanAt(int64_t utime, float x, int32_t epoch, int64_t correction_id) {
  registered_scan_t s = wallScan(utime);
  for (float& px : s.cloud.x) px = x;
  s.epoch = epoch;
  s.correction_id = correction_id;
  return s;
}

loop_correction_t shiftCorrection(int64_t id, int32_t epoch, int64_t previous, const Pose3& T_Ck_O,
                                  const std::vector<std::pair<int64_t, Pose3>>& poses) {
  loop_correction_t m = correction(1, poses);
  m.correction_id = id;
  m.epoch = epoch;
  m.previous_correction_id = previous;
  poseTo(T_Ck_O, m.correction_position, m.correction_orientation);
  poseTo(T_Ck_O, m.odometry_to_corrected_position, m.odometry_to_corrected_orientation);
  return m;
}
}  // namespace

// Real-time hand-offs (lcmtypes/loop_correction_t.lcm): a scan lio published before it adopted a
// correction arrives after the correction moved the map, and is moved onto it (not left in the old
// frame, not corrected twice); a scan in a correction never received is refused; a scan of a new
// odometry epoch writes the old map as <map>_epoch0.* and starts a new one; the old epoch's
// scans and corrections are refused afterwards.
TEST(OctomapNode, LateScansJoinTheCorrectedMapAndANewEpochStartsANewMap) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  livo::octomap::OctomapNodeOptions options;
  options.publish_period_s = 0;
  options.write_period_s = 0;
  options.map_name = "epochs";
  const std::string dir = livo_test::tempPath("octo_epochs");
  livo::octomap::OctomapNode node(lcm, quiet(), options, SensorRig{}, dir);
  auto tree = [&]() {
    octomap_t m;
    const std::string bytes = node.builder().map().binaryBytes();
    m.data.assign(bytes.begin(), bytes.end());
    return m;
  };
  const registered_scan_t first = wallScanAt(1000000, 2.05f, 0, 0);
  lcm.publish("REGISTERED_SCAN", &first);
  const keyframe_t kf0 = wallKeyframe(0, 1000000);
  lcm.publish("KEYFRAME", &kf0);
  drain(lcm);
  ASSERT_EQ(node.builder().scans(), 1);

  // correction 1 lifts the whole odometry frame by 2 m
  Pose3 up = Pose3::Identity();
  up.translation() = Vec3(0.0, 0.0, 2.0);
  const loop_correction_t c1 = shiftCorrection(1, 0, 0, up, {{0, up}});
  lcm.publish("LOOP_CORRECTION", &c1);
  drain(lcm);
  EXPECT_EQ(node.builder().rebuilds(), 1);
  EXPECT_TRUE(occupiedIn(tree(), 2.05, 0.05, 2.05));

  // published by lio before it adopted correction 1 (correction_id 0), arriving now: moved up
  const registered_scan_t late = wallScanAt(1100000, 3.05f, 0, 0);
  lcm.publish("REGISTERED_SCAN", &late);
  // published after lio adopted it (its pose and points already up): used as they are
  registered_scan_t adopted = wallScanAt(1200000, 4.05f, 0, 1);
  adopted.position[2] = 2.0;
  for (float& z : adopted.cloud.z) z += 2.0f;
  lcm.publish("REGISTERED_SCAN", &adopted);
  // in a correction this process never received
  const registered_scan_t unknown = wallScanAt(1300000, 5.05f, 0, 7);
  lcm.publish("REGISTERED_SCAN", &unknown);
  drain(lcm);
  EXPECT_EQ(node.builder().scans(), 3);
  EXPECT_TRUE(occupiedIn(tree(), 3.05, 0.05, 2.05));
  EXPECT_FALSE(occupiedIn(tree(), 3.05, 0.05, 0.05));
  EXPECT_TRUE(occupiedIn(tree(), 4.05, 0.05, 2.05));
  EXPECT_FALSE(occupiedIn(tree(), 4.05, 0.05, 4.05));  // not corrected twice
  EXPECT_FALSE(occupiedIn(tree(), 5.05, 0.05, 0.05));
  EXPECT_FALSE(occupiedIn(tree(), 5.05, 0.05, 2.05));

  // lio reset: epoch 1 restarts the odometry (and its clock went back)
  const registered_scan_t reset = wallScanAt(500000, 6.05f, 1, 0);
  lcm.publish("REGISTERED_SCAN", &reset);
  drain(lcm);
  EXPECT_EQ(node.builder().scans(), 1);  // a new map with this scan only
  EXPECT_EQ(node.builder().keyframes(), 0u);
  EXPECT_TRUE(occupiedIn(tree(), 6.05, 0.05, 0.05));
  EXPECT_FALSE(occupiedIn(tree(), 2.05, 0.05, 2.05));
  ::octomap::OcTree old(0.1);
  ASSERT_TRUE(old.readBinary(dir + "/epochs_epoch0.bt"));
  for (double x : {2.05, 3.05, 4.05}) {
    const ::octomap::OcTreeNode* n = old.search(x, 0.05, 2.05);
    ASSERT_NE(n, nullptr) << x;
    EXPECT_TRUE(old.isNodeOccupied(n)) << x;
  }
  std::unique_ptr<::octomap::AbstractOcTree> old_full(::octomap::AbstractOcTree::read(dir + "/epochs_epoch0.ot"));
  EXPECT_NE(old_full, nullptr);

  // the old epoch afterwards: its scans and corrections are refused, the new map does not move
  const registered_scan_t stale = wallScanAt(1400000, 7.05f, 0, 1);
  lcm.publish("REGISTERED_SCAN", &stale);
  const loop_correction_t c2 = shiftCorrection(2, 0, 1, up, {{0, up}});
  lcm.publish("LOOP_CORRECTION", &c2);
  drain(lcm);
  EXPECT_EQ(node.builder().scans(), 1);
  EXPECT_EQ(node.builder().rebuilds(), 0);
  EXPECT_FALSE(occupiedIn(tree(), 7.05, 0.05, 2.05));
  int64_t rejected = -1;
  for (const channel_stats_t& c : node.node().healthMessage().channels)
    if (c.channel == "REGISTERED_SCAN") rejected = c.rejected;
  EXPECT_EQ(rejected, 2);  // the unknown correction's scan and the old epoch's

  // a correction of the new epoch moves the new map (its keyframe here) by its transform
  const keyframe_t kf1 = wallKeyframe(1, 500000);
  keyframe_t kf1e = kf1;
  kf1e.epoch = 1;
  for (float& x : kf1e.cloud.x) x = 6.05f;
  lcm.publish("KEYFRAME", &kf1e);
  const loop_correction_t c3 = shiftCorrection(3, 1, 0, up, {{1, up}});
  lcm.publish("LOOP_CORRECTION", &c3);
  drain(lcm);
  EXPECT_EQ(node.builder().rebuilds(), 1);
  EXPECT_TRUE(occupiedIn(tree(), 6.05, 0.05, 2.05));
  EXPECT_FALSE(occupiedIn(tree(), 6.05, 0.05, 0.05));
}
