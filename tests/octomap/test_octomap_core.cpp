// The OctoMap core without LCM: free/occupied/unknown on a box scene, .bt/.ot load back with
// octomap's own readers, colours, and the rebuild from corrected keyframes.
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <sstream>
#include <tuple>

#include <gtest/gtest.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include "livo/octomap/morton_index.hpp"
#include "livo/octomap/octomap_builder.hpp"
#include "livo/octomap/octomap_config.hpp"
#include "livo/octomap/ray_keys.hpp"
#include "temp_path.hpp"

using namespace livo;
using namespace livo::octomap;

namespace {

/// Rays from `origin` in all directions into a closed box room [-2.05, 2.05]^2 x [0.05, 2.45] with
/// a solid crate [0.85, 1.25] x [-0.25, 0.25] x [0, 1.25]: the first surface each ray hits (world frame).
std::vector<Eigen::Vector3f> boxRoomHits(const Eigen::Vector3d& origin) {
  std::vector<Eigen::Vector3f> pts;
  // surfaces mid-voxel (a surface on a voxel boundary would put its hits on either side at random)
  const Eigen::Vector3d lo(-2.05, -2.05, 0.05), hi(2.05, 2.05, 2.45), clo(0.85, -0.25, 0), chi(1.25, 0.25, 1.25);
  for (int i = 0; i < 360; ++i) {
    for (int j = -60; j <= 80; ++j) {
      const double az = i * M_PI / 180.0, el = j * 0.75 * M_PI / 180.0;
      const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      double t_exit = 1e9;
      for (int k = 0; k < 3; ++k) {
        if (d[k] > 1e-12) t_exit = std::min(t_exit, (hi[k] - origin[k]) / d[k]);
        if (d[k] < -1e-12) t_exit = std::min(t_exit, (lo[k] - origin[k]) / d[k]);
      }
      double t0 = 0, t1 = 1e9;  // slab test against the crate
      bool crate = true;
      for (int k = 0; k < 3 && crate; ++k) {
        if (std::abs(d[k]) < 1e-12) {
          crate = origin[k] >= clo[k] && origin[k] <= chi[k];
          continue;
        }
        double a = (clo[k] - origin[k]) / d[k], b = (chi[k] - origin[k]) / d[k];
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a), t1 = std::min(t1, b);
        crate = t0 <= t1;
      }
      const double t = crate ? std::min(t0, t_exit) : t_exit;
      pts.push_back((origin + t * d).cast<float>());
    }
  }
  return pts;
}

OctomapOptions options(bool colour) {
  OctomapOptions o;
  o.resolution = 0.1;
  o.colour = colour;
  return o;
}

}  // namespace

TEST(OccupancyMap, ClassifiesFreeOccupiedAndUnknownInABoxRoom) {
  OccupancyMap map(options(false));
  const Eigen::Vector3d origin(-0.5, 0.3, 1.2);
  for (int k = 0; k < 3; ++k) EXPECT_GT(map.insertRays(boxRoomHits(origin), origin), 40000u);
  EXPECT_EQ(map.classify(Eigen::Vector3d(-2.05, 0.0, 1.0)), 1);    // west wall
  EXPECT_EQ(map.classify(Eigen::Vector3d(0.0, 2.05, 1.0)), 1);     // north wall
  EXPECT_EQ(map.classify(Eigen::Vector3d(-1.85, 0.35, 0.05)), 1);  // floor (within the 45° down-looking beams)
  EXPECT_EQ(map.classify(Eigen::Vector3d(0.85, 0.0, 0.6)), 1);     // crate face towards the sensor
  EXPECT_EQ(map.classify(Eigen::Vector3d(0.0, 0.0, 1.2)), 0);      // open room
  EXPECT_EQ(map.classify(Eigen::Vector3d(-1.0, -1.0, 2.0)), 0);
  EXPECT_EQ(map.classify(Eigen::Vector3d(1.6, 0.0, 0.5)), -1);   // in the crate's shadow
  EXPECT_EQ(map.classify(Eigen::Vector3d(1.05, 0.0, 0.6)), -1);  // inside the crate
  EXPECT_EQ(map.classify(Eigen::Vector3d(3.0, 0.0, 1.0)), -1);   // outside the room
  // occupied voxels lie on the surfaces, not in the room's free middle
  const auto occupied = map.occupiedVoxels();
  EXPECT_GT(occupied.size(), 1000u);
  for (const Eigen::Vector3d& c : occupied) {
    const bool on_wall = std::abs(c.x()) > 1.95 || std::abs(c.y()) > 1.95 || c.z() < 0.15 || c.z() > 2.35;
    const bool on_crate = c.x() > 0.75 && c.x() < 1.35 && std::abs(c.y()) < 0.35 && c.z() < 1.35;
    EXPECT_TRUE(on_wall || on_crate) << c.transpose();
  }
}

TEST(OccupancyMap, MaxRangeOnlyClearsAndNonFinitePointsAreSkipped) {
  OctomapOptions o = options(false);
  o.max_range = 1.0;
  OccupancyMap map(o);
  std::vector<Eigen::Vector3f> pts{{3.0f, 0.05f, 0.05f}, {NAN, 0.f, 0.f}, {0.05f, 0.05f, 0.1f}};
  EXPECT_EQ(map.insertRays(pts, Eigen::Vector3d::Zero()), 1u);  // the too-near one is dropped too
  EXPECT_EQ(map.classify(Eigen::Vector3d(0.55, 0.05, 0.05)), 0);
  EXPECT_EQ(map.classify(Eigen::Vector3d(2.95, 0.05, 0.05)), -1);
}

TEST(OccupancyMap, BtAndOtFilesLoadBackWithOctomapsReaders) {
  for (const bool colour : {false, true}) {
    OccupancyMap map(options(colour));
    const Eigen::Vector3d origin(0.0, 0.0, 1.0);
    map.insertRays(boxRoomHits(origin), origin);
    if (colour) {
      std::vector<Eigen::Vector3f> p{{-2.05f, 0.05f, 1.05f}};
      EXPECT_EQ(map.setColours(p, {{{200, 10, 30}}}), 1u);
    }
    const std::string bt = livo_test::tempPath(colour ? "c.bt" : "p.bt"),
                      ot = livo_test::tempPath(colour ? "c.ot" : "p.ot");
    ASSERT_TRUE(map.writeBinary(bt));
    ASSERT_TRUE(map.writeFull(ot));
    const size_t occupied = map.occupiedVoxels().size();

    ::octomap::OcTree from_bt(0.1);
    ASSERT_TRUE(from_bt.readBinary(bt));
    EXPECT_DOUBLE_EQ(from_bt.getResolution(), 0.1);
    size_t bt_occupied = 0;
    for (auto it = from_bt.begin_leafs(); it != from_bt.end_leafs(); ++it)
      if (from_bt.isNodeOccupied(*it)) bt_occupied += static_cast<size_t>(std::lround(std::pow(it.getSize() / 0.1, 3)));
    EXPECT_EQ(bt_occupied, occupied);
    ASSERT_NE(from_bt.search(-2.05, 0.0, 1.0), nullptr);
    EXPECT_TRUE(from_bt.isNodeOccupied(from_bt.search(-2.05, 0.0, 1.0)));

    std::unique_ptr<::octomap::AbstractOcTree> any(::octomap::AbstractOcTree::read(ot));
    ASSERT_NE(any, nullptr);
    EXPECT_EQ(any->getTreeType(), colour ? "ColorOcTree" : "OcTree");
    if (colour) {
      auto* t = dynamic_cast<::octomap::ColorOcTree*>(any.get());
      ASSERT_NE(t, nullptr);
      const ::octomap::ColorOcTreeNode* n = t->search(-2.05, 0.05, 1.05);
      ASSERT_NE(n, nullptr);
      EXPECT_EQ(n->getColor().r, 200);
      EXPECT_EQ(n->getColor().g, 10);
      EXPECT_EQ(n->getColor().b, 30);
    }
  }
}

TEST(OctomapBuilder, RebuildsFromCorrectedKeyframes) {
  OctomapBuilder builder(options(false), Pose3::Identity());
  Keyframe k;
  k.utime = 1000000;
  k.T_W_I = Pose3::Identity();
  for (int i = -5; i <= 5; ++i)
    for (int j = 0; j <= 10; ++j) k.points.emplace_back(3.05f, 0.1f * i + 0.05f, 0.1f * j + 0.05f);  // a wall 3 m ahead
  std::vector<float> x, y, z, dt;
  for (const auto& p : k.points) x.push_back(p.x()), y.push_back(p.y()), z.push_back(p.z()), dt.push_back(0.f);
  RegisteredScanView v;
  v.utime = 1100000;
  v.cloud_utime = 1000000;
  v.num_points = static_cast<int>(x.size());
  v.x = x.data(), v.y = y.data(), v.z = z.data(), v.time_offset = dt.data();
  std::string error;
  ASSERT_TRUE(builder.addScan(v, &error)) << error;
  EXPECT_FALSE(builder.addScan(v, &error));  // stale
  builder.addKeyframe(0, k);
  EXPECT_EQ(builder.map().classify(Eigen::Vector3d(3.05, 0.05, 0.55)), 1);
  Pose3 corrected = Pose3::Identity();
  corrected.translation() = Vec3(0.0, 0.0, 2.0);
  EXPECT_EQ(builder.applyCorrection({{0, corrected}, {7, corrected}}), 1);
  EXPECT_EQ(builder.rebuilds(), 1);
  EXPECT_EQ(builder.map().classify(Eigen::Vector3d(3.05, 0.05, 0.55)), -1);
  EXPECT_EQ(builder.map().classify(Eigen::Vector3d(3.05, 0.05, 2.55)), 1);
}

namespace {
// A wall of points 3 m ahead of `origin` along +x (or behind it, along -x), world frame.
std::vector<Eigen::Vector3f> wallAhead(const Eigen::Vector3f& origin, float direction = 1.f) {
  std::vector<Eigen::Vector3f> pts;
  for (int i = -5; i <= 5; ++i)
    for (int j = 0; j <= 10; ++j)
      pts.push_back(origin + Eigen::Vector3f(direction * 3.05f, 0.1f * i + 0.05f, 0.1f * j + 0.05f));
  return pts;
}
struct ScanArrays {
  std::vector<float> x, y, z, dt;
  RegisteredScanView view(int64_t utime, const std::vector<Eigen::Vector3f>& pts, const Pose3& T_W_I) {
    x.clear(), y.clear(), z.clear(), dt.clear();
    for (const auto& p : pts) x.push_back(p.x()), y.push_back(p.y()), z.push_back(p.z()), dt.push_back(0.f);
    RegisteredScanView v;
    v.utime = utime;
    v.cloud_utime = utime - 100000;
    v.num_points = static_cast<int>(x.size());
    v.x = x.data(), v.y = y.data(), v.z = z.data(), v.time_offset = dt.data();
    v.T_W_I = T_W_I;
    return v;
  }
};
}  // namespace

// A staged rebuild (rebuild_keyframes_per_scan 1): after the correction the map is the old one
// until the scans have cast every kept keyframe into the second tree, which then holds the
// keyframes at their corrected poses and the sweeps since the correction.
TEST(OctomapBuilder, AStagedRebuildReplacesTheMapWhenEveryKeyframeIsCast) {
  OctomapOptions o = options(false);
  o.rebuild_keyframes_per_scan = 1;
  OctomapBuilder builder(o, Pose3::Identity());
  ScanArrays arrays;
  std::string error;
  for (int i = 0; i < 3; ++i) {
    Pose3 T = Pose3::Identity();
    T.translation() = Vec3(0.0, 0.4 * i, 0.0);
    Keyframe k;
    k.utime = 1000000 + i * 100000;
    k.T_W_I = T;
    for (const auto& p : wallAhead(Eigen::Vector3f::Zero())) k.points.push_back(p);  // body frame
    std::vector<Eigen::Vector3f> world;
    for (const auto& p : k.points) world.push_back((T * p.cast<double>()).cast<float>());
    ASSERT_TRUE(builder.addScan(arrays.view(k.utime, world, T), &error)) << error;
    builder.addKeyframe(i, k);
  }
  EXPECT_EQ(builder.map().classify(Eigen::Vector3d(3.05, 0.05, 0.55)), 1);
  std::map<int64_t, Pose3> corrected;
  for (int i = 0; i < 3; ++i) {
    Pose3 T = Pose3::Identity();
    T.translation() = Vec3(0.0, 0.4 * i, 2.0);
    corrected[i] = T;
  }
  EXPECT_EQ(builder.applyCorrection(corrected), 3);
  EXPECT_TRUE(builder.lastCorrectionRebuilt());
  EXPECT_TRUE(builder.rebuilding());
  EXPECT_EQ(builder.rebuilds(), 0);
  EXPECT_EQ(builder.map().classify(Eigen::Vector3d(3.05, 0.05, 0.55)), 1);  // still the old map
  // the sweeps after the correction look the other way
  Pose3 now = corrected[2];
  for (int s = 0; s < 3; ++s) {
    const int64_t t = 2000000 + s * 100000;
    EXPECT_FALSE(builder.takeRebuildFinished());
    ASSERT_TRUE(builder.addScan(arrays.view(t, wallAhead(now.translation().cast<float>(), -1.f), now), &error))
        << error;
    EXPECT_EQ(builder.rebuilding(), s < 2) << s;
  }
  EXPECT_TRUE(builder.takeRebuildFinished());
  EXPECT_FALSE(builder.takeRebuildFinished());
  EXPECT_EQ(builder.rebuilds(), 1);
  EXPECT_EQ(builder.map().classify(Eigen::Vector3d(3.05, 0.05, 0.55)), -1);  // the old wall is gone
  EXPECT_EQ(builder.map().classify(Eigen::Vector3d(3.05, 0.05, 2.55)), 1);   // the keyframes' wall, moved
  EXPECT_EQ(builder.map().classify(Eigen::Vector3d(-3.05, 0.85, 2.55)), 1);  // the sweeps since
}

// keyframe_spacing: keyframes nearer than it to a kept one are not kept for rebuilds.
TEST(OctomapBuilder, KeyframesNearAKeptOneAreNotKept) {
  OctomapOptions o = options(false);
  o.keyframe_spacing = 1.0;
  OctomapBuilder builder(o, Pose3::Identity());
  for (int i = 0; i < 10; ++i) {
    Keyframe k;
    k.utime = 1000000 + i * 100000;
    k.T_W_I.translation() = Vec3(0.4 * i, 0.0, 0.0);
    k.points = wallAhead(Eigen::Vector3f::Zero());
    EXPECT_TRUE(builder.addKeyframe(i, k));
  }
  // kept: 0, 1.2, 2.4, 3.6 m (each the first at 1 m or more from every kept one)
  EXPECT_EQ(builder.keyframes(), 4u);
  EXPECT_EQ(builder.keyframesNotKept(), 6);
}

// After a loop correction the tree holds exactly the keyframes' clouds at their corrected poses,
// each ray-cast from that keyframe's LiDAR origin T_W_I * T_I_L (not the body origin): a keyframe
// whose pose changed moves its wall and its free space, an unchanged one stays, and the sweeps
// registered before the correction are gone.
TEST(OctomapBuilder, RebuildCastsEachCorrectedKeyframeFromItsLidarOrigin) {
  Pose3 T_I_L = Pose3::Identity();
  T_I_L.linear() = so3::Exp(Vec3(0.0, 0.0, 30.0 * M_PI / 180.0));  // must not touch the body-frame points
  T_I_L.translation() = Vec3(0.5, 0.0, 1.0);
  OctomapBuilder builder(options(false), T_I_L);

  // keyframe 0: a wall 2.55 m ahead of the body; keyframe 1: a wall 2.55 m behind it
  Pose3 odom = Pose3::Identity();
  odom.translation() = Vec3(0.0, 0.05, 0.0);
  Keyframe ahead, behind;
  ahead.utime = 1000000;
  behind.utime = 2000000;
  ahead.T_W_I = behind.T_W_I = odom;
  for (int k = -9; k <= 9; ++k)
    for (int j = 0; j < 20; ++j) {
      ahead.points.emplace_back(2.55f, 0.1f * k, 0.05f + 0.1f * j);
      behind.points.emplace_back(-2.55f, 0.1f * k, 0.05f + 0.1f * j);
    }
  // the sweep registered at keyframe 0 (world frame = odometry frame)
  std::vector<float> x, y, z, dt;
  for (const Eigen::Vector3f& p : ahead.points) {
    const Eigen::Vector3f w = (odom * p.cast<double>()).cast<float>();
    x.push_back(w.x()), y.push_back(w.y()), z.push_back(w.z()), dt.push_back(0.f);
  }
  RegisteredScanView v;
  v.utime = 1000000;
  v.cloud_utime = 900000;
  v.T_W_I = odom;
  v.num_points = static_cast<int>(x.size());
  v.x = x.data(), v.y = y.data(), v.z = z.data(), v.time_offset = dt.data();
  std::string error;
  ASSERT_TRUE(builder.addScan(v, &error)) << error;
  builder.addKeyframe(0, ahead);
  builder.addKeyframe(1, behind);
  const Eigen::Vector3d old_wall(2.55, 0.05, 0.55), new_wall(0.95, 2.55, 0.55), back_wall(-2.55, 0.05, 0.55);
  EXPECT_EQ(builder.map().classify(old_wall), 1);
  EXPECT_EQ(builder.map().classify(back_wall), -1);  // keyframes alone do not enter the tree

  // keyframe 0 turns out to have been 1.05 m further along x and turned left by 90 degrees
  Pose3 corrected = Pose3::Identity();
  corrected.linear() = so3::Exp(Vec3(0.0, 0.0, M_PI / 2));
  corrected.translation() = Vec3(1.05, 0.0, 0.0);
  EXPECT_EQ(builder.applyCorrection({{0, corrected}, {1, odom}, {9, corrected}}), 1);  // 1 unchanged, 9 unknown
  EXPECT_EQ(builder.rebuilds(), 1);
  EXPECT_EQ(builder.map().classify(new_wall), 1);   // keyframe 0's wall at its corrected pose
  EXPECT_EQ(builder.map().classify(back_wall), 1);  // keyframe 1 at its (unchanged) pose
  EXPECT_EQ(builder.map().classify(old_wall), -1);  // the old sweep and the old pose are gone
  // free space from keyframe 0's LiDAR origin, (1.05, 0.5, 1.0) in the world, to its wall ...
  const Eigen::Vector3d lidar = (corrected * T_I_L).translation();
  EXPECT_NEAR((lidar - Eigen::Vector3d(1.05, 0.5, 1.0)).norm(), 0.0, 1e-9);
  EXPECT_EQ(builder.map().classify(Eigen::Vector3d(1.05, 1.5, 1.02)), 0);
  // ... and none at the body's height under it: a ray cast from the body origin would clear it
  EXPECT_EQ(builder.map().classify(Eigen::Vector3d(1.05, 0.95, 0.05)), -1);
  // every occupied voxel is on one of the two walls
  for (const Eigen::Vector3d& c : builder.map().occupiedVoxels())
    EXPECT_TRUE(std::abs(c.y() - 2.55) < 0.06 || std::abs(c.x() + 2.55) < 0.06) << c.transpose();

  // a correction that moves nothing does not rebuild
  EXPECT_EQ(builder.applyCorrection({{0, corrected}}), 0);
  EXPECT_EQ(builder.rebuilds(), 1);
}

// A correction that moves the keyframes' points by less than rebuild_tolerance keeps the tree; the
// shift is measured from the poses the tree has, so small corrections that add up do rebuild, and
// a small turn of a keyframe with far points counts with the distance it moves them.
TEST(OctomapBuilder, RebuildsOnlyWhenPointsMoveBeyondTheTolerance) {
  OctomapOptions o = options(false);
  ASSERT_DOUBLE_EQ(o.rebuild_tolerance, 0.05);
  OctomapBuilder builder(o, Pose3::Identity());
  Keyframe k;
  k.utime = 1000000;
  for (int i = -5; i <= 5; ++i) k.points.emplace_back(10.05f, 0.1f * i + 0.05f, 0.55f);  // a wall 10 m ahead
  ASSERT_TRUE(builder.addKeyframe(0, k));
  auto shifted = [](double x, double yaw_deg) {
    Pose3 T = Pose3::Identity();
    T.linear() = so3::Exp(Vec3(0.0, 0.0, yaw_deg * M_PI / 180.0));
    T.translation() = Vec3(x, 0.0, 0.0);
    return T;
  };
  EXPECT_EQ(builder.applyCorrection({{0, shifted(0.02, 0.0)}}), 1);
  EXPECT_NEAR(builder.lastCorrectionShift(), 0.02, 1e-9);
  EXPECT_FALSE(builder.lastCorrectionRebuilt());
  EXPECT_EQ(builder.rebuilds(), 0);
  EXPECT_EQ(builder.applyCorrection({{0, shifted(0.04, 0.0)}}), 1);  // 0.04 from the tree's pose
  EXPECT_EQ(builder.rebuilds(), 0);
  EXPECT_EQ(builder.applyCorrection({{0, shifted(0.06, 0.0)}}), 1);  // 0.06: beyond
  EXPECT_TRUE(builder.lastCorrectionRebuilt());
  EXPECT_EQ(builder.rebuilds(), 1);
  EXPECT_EQ(builder.map().classify(Eigen::Vector3d(10.15, 0.05, 0.55)), 1);  // the wall at x + 0.06
  // 0.4 degrees move the wall's points (up to 10.06 m away) by about 7 cm
  EXPECT_EQ(builder.applyCorrection({{0, shifted(0.06, 0.4)}}), 1);
  EXPECT_NEAR(builder.lastCorrectionShift(),
              2.0 * std::sin(0.2 * M_PI / 180.0) * std::sqrt(10.05 * 10.05 + 2 * 0.55 * 0.55), 1e-6);
  EXPECT_EQ(builder.rebuilds(), 2);
  // with no tolerance any change rebuilds
  o.rebuild_tolerance = 0.0;
  OctomapBuilder strict(o, Pose3::Identity());
  ASSERT_TRUE(strict.addKeyframe(0, k));
  EXPECT_EQ(strict.applyCorrection({{0, shifted(0.001, 0.0)}}), 1);
  EXPECT_EQ(strict.rebuilds(), 1);
}

TEST(OctomapConfig, ReadsKeysStrictly) {
  const auto o = readOctomapNodeOptions(Config::fromString("octomap: {resolution: 0.2, colour: true}"));
  EXPECT_DOUBLE_EQ(o.core.resolution, 0.2);
  EXPECT_TRUE(o.core.colour);
  EXPECT_THROW(readOctomapNodeOptions(Config::fromString("octomap: {resolutoin: 0.2}")), ConfigError);
  EXPECT_THROW(readOctomapNodeOptions(Config::fromString("octomap: {prob_hit: 0.3}")), ConfigError);
}

namespace {
// floor hits on the line y = 0.05, z = 0.05 (mid-voxel) for x in [x0, x1)
std::vector<Eigen::Vector3f> floorLine(double x0, double x1) {
  std::vector<Eigen::Vector3f> pts;
  for (double x = x0; x < x1; x += 0.02) pts.emplace_back(float(x), 0.05f, 0.05f);
  return pts;
}
}  // namespace

// Grazing rays to farther floor points pass through the floor voxels just before their own
// endpoints: without free_margin they clear the floor seen before; with it they do not, and the
// space above stays free.
TEST(OccupancyMap, FreeMarginKeepsGrazingRaysFromClearingTheSurface) {
  const Eigen::Vector3d origin(0.0, 0.05, 0.5);
  const Eigen::Vector3d seen(3.95, 0.05, 0.05), above(1.05, 0.05, 0.35);
  for (const double margin : {0.0, 0.2}) {
    OctomapOptions o = options(false);
    o.free_margin = margin;
    OccupancyMap map(o);
    map.insertRays(floorLine(1.0, 4.0), origin);
    EXPECT_EQ(map.classify(seen), 1);
    for (int k = 0; k < 3; ++k) map.insertRays(floorLine(4.12, 4.18), origin);
    EXPECT_EQ(map.classify(seen), margin > 0 ? 1 : 0) << "free_margin " << margin;
    EXPECT_EQ(map.classify(above), 0) << "free_margin " << margin;
  }
}

// A sweep cast from several origins is one update: a voxel crossed by rays of several slices
// takes one miss, and an endpoint of one slice is not cleared by another slice's rays.
TEST(OccupancyMap, SweepSlicesAreOneUpdate) {
  OctomapOptions o = options(false);
  o.free_margin = 0.0;
  OccupancyMap map(o);
  const std::vector<Eigen::Vector3f> near{{1.05f, 0.05f, 0.05f}}, far{{3.05f, 0.05f, 0.05f}};
  std::vector<OccupancyMap::Slice> slices(2);
  slices[0].origin = slices[1].origin = Eigen::Vector3d(0.05, 0.05, 0.05);
  slices[0].points = &near;  // its endpoint lies on the other slice's ray
  slices[1].points = &far;
  EXPECT_EQ(map.insertSweep(slices), 2u);
  EXPECT_EQ(map.classify(Eigen::Vector3d(1.05, 0.05, 0.05)), 1);
  EXPECT_EQ(map.classify(Eigen::Vector3d(3.05, 0.05, 0.05)), 1);
  EXPECT_EQ(map.classify(Eigen::Vector3d(0.55, 0.05, 0.05)), 0);
  // one miss per sweep: the log-odds of a voxel both rays crossed is that of a single miss
  const float one_miss = ::octomap::logodds(o.prob_miss);
  std::istringstream in(map.fullBytes());
  std::unique_ptr<::octomap::AbstractOcTree> read(::octomap::AbstractOcTree::read(in));
  auto* tree = dynamic_cast<::octomap::OcTree*>(read.get());
  ASSERT_NE(tree, nullptr);
  const ::octomap::OcTreeNode* n = tree->search(0.55, 0.05, 0.05);
  ASSERT_NE(n, nullptr);
  EXPECT_NEAR(n->getLogOdds(), one_miss, 1e-4);
}

// forEachRayKey lists exactly the keys octomap's computeRayKeys does, in its order: random rays,
// rays from and to voxel borders and centres, axis-parallel and diagonal ones, short and long.
TEST(RayKeys, SameKeysAsOctomapsComputeRayKeys) {
  for (const double res : {0.1, 0.05, 0.2}) {
    ::octomap::OcTree tree(res);
    std::mt19937 rng(42);
    std::uniform_real_distribution<float> pos(-40.f, 40.f), off(-3.f, 3.f);
    std::uniform_int_distribution<int> cell(-400, 400), kind(0, 5);
    ::octomap::KeyRay ray;
    std::vector<::octomap::OcTreeKey> mine;
    size_t keys = 0;
    for (int n = 0; n < 60000; ++n) {
      auto on_grid = [&](float half) {  // a voxel border (half = 0) or centre (half = 0.5)
        return ::octomap::point3d(float((cell(rng) + half) * res), float((cell(rng) + half) * res),
                                  float((cell(rng) + half) * res));
      };
      ::octomap::point3d o(pos(rng), pos(rng), pos(rng)), e(pos(rng), pos(rng), pos(rng));
      switch (kind(rng)) {
        case 1: o = on_grid(0.f), e = on_grid(0.5f); break;
        case 2: o = on_grid(0.5f), e = on_grid(0.f); break;
        case 3: e = o + ::octomap::point3d(off(rng), 0.f, 0.f); break;  // axis-parallel
        case 4: {                                                       // diagonal
          const float d = off(rng);
          e = o + ::octomap::point3d(d, d, (n % 2) ? d : -d);
          break;
        }
        case 5: e = o + ::octomap::point3d(off(rng), off(rng), off(rng)) * 0.05f; break;  // short
        default: break;
      }
      ::octomap::OcTreeKey ok;
      ASSERT_TRUE(tree.coordToKeyChecked(o, ok));
      const bool expected = tree.computeRayKeys(o, e, ray);
      mine.clear();
      const bool got = forEachRayKey(tree, o, ok, e, [&](const ::octomap::OcTreeKey& k) { mine.push_back(k); });
      ASSERT_EQ(got, expected);
      ASSERT_EQ(mine.size(), ray.size()) << "ray " << n << " at " << res;
      ASSERT_TRUE(std::equal(mine.begin(), mine.end(), ray.begin())) << "ray " << n << " at " << res;
      keys += mine.size();
    }
    EXPECT_GT(keys, 300000u);
  }
}

namespace {
constexpr int kCheckBits = 4;
struct StepChecker {  // a walkRayKeys walker
  std::function<unsigned(const ::octomap::OcTreeKey&)> idx;
  ::octomap::OcTreeKey prev;
  unsigned i = 0;  // the index moved along with the steps
  size_t steps = 0, crossings = 0, failures = 0;
  void start(const ::octomap::OcTreeKey& k) {
    prev = k;
    i = idx(k);
  }
  template <int A>
  void step(int dir, const ::octomap::OcTreeKey& k) {
    ::octomap::OcTreeKey want = prev;
    want[A] = static_cast<::octomap::key_type>(want[A] + dir);
    const bool leaves = dir > 0 ? morton::atTop<A, kCheckBits>(i) : morton::atBottom<A, kCheckBits>(i);
    crossings += leaves;
    i = dir > 0 ? morton::up<A, kCheckBits>(i) : morton::down<A, kCheckBits>(i);
    failures += !(k == want) || (dir != 1 && dir != -1) || i != idx(k) ||
                leaves != ((prev[A] >> kCheckBits) != (k[A] >> kCheckBits));
    prev = k;
    ++steps;
  }
};
}  // namespace

// The ray walk's steps move the key by one along the axis they name, and the Morton index moved
// along with them (morton::up/down, wrapping at a block's faces where atTop/atBottom say so) is the
// index interleaved from the key, along random rays crossing many 16^3 blocks.
TEST(RayKeys, StepsMoveTheKeyAndTheMortonIndexByOne) {
  constexpr int kBits = kCheckBits;
  constexpr unsigned kM = (1u << kBits) - 1;
  auto idx = [](const ::octomap::OcTreeKey& k) { return morton::index<kBits>(k[0] & kM, k[1] & kM, k[2] & kM); };
  ::octomap::OcTree tree(0.1);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> pos(-30.f, 30.f);
  StepChecker w;
  w.idx = idx;
  for (int n = 0; n < 5000; ++n) {
    const ::octomap::point3d o(pos(rng), pos(rng), pos(rng)), e(pos(rng), pos(rng), pos(rng));
    ::octomap::OcTreeKey ok;
    ASSERT_TRUE(tree.coordToKeyChecked(o, ok));
    walkRayKeys(tree, o, ok, e, w);
    ASSERT_EQ(w.failures, 0u) << "ray " << n;
  }
  EXPECT_GT(w.steps, 1000000u);
  EXPECT_GT(w.crossings, 50000u);
  // every lane value up and down, on each axis
  for (unsigned i = 0; i < (1u << (3 * kBits)); ++i) {
    const unsigned x = i & 0x249u, y = i & 0x492u, z = i & 0x924u;
    auto coord = [](unsigned v, int a) {
      unsigned c = 0;
      for (int j = 0; j < kBits; ++j) c |= ((v >> (3 * j + a)) & 1u) << j;
      return c;
    };
    const unsigned cx = coord(x, 0), cy = coord(y, 1), cz = coord(z, 2);
    ASSERT_EQ((morton::up<0, kBits>(i)), (morton::index<kBits>((cx + 1) & kM, cy, cz)));
    ASSERT_EQ((morton::down<1, kBits>(i)), (morton::index<kBits>(cx, (cy - 1) & kM, cz)));
    ASSERT_EQ((morton::up<2, kBits>(i)), (morton::index<kBits>(cx, cy, (cz + 1) & kM)));
    ASSERT_EQ((morton::atTop<0, kBits>(i)), cx == kM);
    ASSERT_EQ((morton::atBottom<2, kBits>(i)), cz == 0u);
  }
}

// A sweep's map is what octomap's own per-key updates make of the sweep: the keys of every ray
// (computeRayKeys) miss once, endpoints hit once, each voxel once a sweep; several sweeps across
// several tiles and blocks, tiles pruned between sweeps (updates expand them again).
TEST(OccupancyMap, SweepsMakeWhatOctomapsPerKeyUpdatesMake) {
  OctomapOptions o = options(false);
  o.free_margin = 0.0;
  o.min_range = 0.0;
  o.max_range = 0.0;
  o.tile_size = 1.6;
  OccupancyMap map(o);
  ::octomap::OcTree ref(o.resolution);
  ref.setProbHit(o.prob_hit);
  ref.setProbMiss(o.prob_miss);
  ref.setClampingThresMin(o.clamping_min);
  ref.setClampingThresMax(o.clamping_max);
  ref.setOccupancyThres(o.occupancy_threshold);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> pos(-6.f, 6.f);
  ::octomap::KeyRay ray;
  for (int sweep = 0; sweep < 10; ++sweep) {
    std::vector<OccupancyMap::Slice> slices(3);
    std::vector<std::vector<Eigen::Vector3f>> points(slices.size());
    ::octomap::KeySet free, hit;
    for (size_t i = 0; i < slices.size(); ++i) {
      slices[i].origin = Eigen::Vector3d(0.3 * sweep + 0.1 * double(i), 0.2, 0.4 * double(i));
      slices[i].points = &points[i];
      const ::octomap::point3d origin(float(slices[i].origin.x()), float(slices[i].origin.y()),
                                      float(slices[i].origin.z()));
      for (int k = 0; k < 3000; ++k) {
        const Eigen::Vector3f p(pos(rng), pos(rng), 0.5f * pos(rng));
        points[i].push_back(p);
        const ::octomap::OcTreeKey key = ref.coordToKey(::octomap::point3d(p.x(), p.y(), p.z()));
        hit.insert(key);
        ASSERT_TRUE(ref.computeRayKeys(origin, ref.keyToCoord(key), ray));
        free.insert(ray.begin(), ray.end());
      }
    }
    map.insertSweep(slices);
    for (int i = 0; i < 40; ++i) map.evictIdle();  // prunes resident tiles in turn: later updates expand them
    for (const auto& k : free)
      if (!hit.count(k)) ref.updateNode(k, ref.getProbMissLog(), true);
    for (const auto& k : hit) ref.updateNode(k, ref.getProbHitLog(), true);
  }
  ref.updateInnerOccupancy();
  std::istringstream in(map.fullBytes());
  std::unique_ptr<::octomap::AbstractOcTree> read(::octomap::AbstractOcTree::read(in));
  auto* tree = dynamic_cast<::octomap::OcTree*>(read.get());
  ASSERT_NE(tree, nullptr);
  tree->prune();
  ref.prune();
  EXPECT_EQ(tree->getNumLeafNodes(), ref.getNumLeafNodes());
  size_t compared = 0;
  for (auto it = ref.begin_leafs(), end = ref.end_leafs(); it != end; ++it) {
    const ::octomap::OcTreeNode* n = tree->search(it.getKey());
    ASSERT_NE(n, nullptr);
    ASSERT_EQ(n->getLogOdds(), it->getLogOdds());
    ++compared;
  }
  EXPECT_GT(compared, 20000u);
}

TEST(OctomapConfig, FreeMarginAndRebuildToleranceAreReadAndChecked) {
  EXPECT_DOUBLE_EQ(readOctomapNodeOptions(livo::Config::fromString("octomap: {free_margin: 0.3}")).core.free_margin,
                   0.3);
  EXPECT_THROW(readOctomapNodeOptions(livo::Config::fromString("octomap: {free_margin: -0.1}")), livo::ConfigError);
  EXPECT_DOUBLE_EQ(
      readOctomapNodeOptions(livo::Config::fromString("octomap: {rebuild_tolerance: 0}")).core.rebuild_tolerance, 0.0);
  EXPECT_THROW(readOctomapNodeOptions(livo::Config::fromString("octomap: {rebuild_tolerance: -0.01}")),
               livo::ConfigError);
  const OctomapOptions tiles =
      readOctomapNodeOptions(livo::Config::fromString("octomap: {tile_size: 12.8, tile_idle_s: 2}")).core;
  EXPECT_DOUBLE_EQ(tiles.tile_size, 12.8);
  EXPECT_DOUBLE_EQ(tiles.tile_idle_s, 2.0);
  EXPECT_DOUBLE_EQ(readOctomapNodeOptions(livo::Config::fromString("octomap: {tile_size: 0}")).core.tile_size, 0.0);
  EXPECT_THROW(readOctomapNodeOptions(livo::Config::fromString("octomap: {tile_size: 0.1}")),
               livo::ConfigError);  // one voxel
  EXPECT_THROW(readOctomapNodeOptions(livo::Config::fromString("octomap: {tile_idle_s: -1}")), livo::ConfigError);
}

// The keyframe clouds are kept on disk quantised to keyframe_step (1 cm): a rebuild from them
// must agree with a rebuild from the clouds as received (keyframe_step 0: float, exact) at least
// as well as two rebuilds from the same scene with different draws of the sensor's own 1 cm
// range noise agree with each other: quantising (error <= 5 mm per axis) must disturb the tree
// less than the noise it is built from already does. The walls lie across voxel boundaries after
// the correction (rotated and shifted), so a few per cent of the occupied voxels are marginal
// either way. Measured (intersection over union of occupied voxels at 0.1 m): quantised (1 cm) vs
// full 0.967, one noise draw vs another 0.937; for scale, steps of 0.5 / 2 / 5 cm give 0.983 /
// 0.962 / 0.844. The floor 0.95 leaves the measured 0.967 room for compilers' float differences
// while still failing for a step of 5 cm, or a store that loses points.
TEST(OctomapBuilder, RebuildFromTheQuantisedStoreAgreesWithFullClouds) {
  auto build = [](double step, unsigned seed) {
    OctomapOptions o = options(false);
    o.keyframe_step = step;
    o.rebuild_tolerance = 0.0;
    auto builder = std::make_unique<OctomapBuilder>(o, Pose3::Identity());
    std::mt19937 r(seed);
    std::normal_distribution<float> noise(0.f, 0.01f);
    for (int i = 0; i < 6; ++i) {
      Keyframe k;
      k.utime = 1000000 * (i + 1);
      k.T_W_I = Pose3::Identity();
      k.T_W_I.translation() = Vec3(-1.0 + 0.4 * i, 0.3 * std::sin(i), 1.2);
      for (const Eigen::Vector3f& p : boxRoomHits(k.T_W_I.translation()))
        k.points.push_back((p - k.T_W_I.translation().cast<float>()) + Eigen::Vector3f(noise(r), noise(r), noise(r)));
      EXPECT_TRUE(builder->addKeyframe(i, k));
    }
    std::map<int64_t, Pose3> corrected;
    for (int i = 0; i < 6; ++i) {
      Pose3 T = Pose3::Identity();
      T.linear() = Eigen::AngleAxisd(0.01 * i, Vec3::UnitZ()).toRotationMatrix();
      T.translation() = Vec3(-1.0 + 0.4 * i + 0.03, 0.3 * std::sin(i), 1.2);
      corrected[i] = T;
    }
    builder->applyCorrection(corrected);
    EXPECT_EQ(builder->rebuilds(), 1);
    return builder;
  };
  auto keys = [](const OctomapBuilder& b) {
    std::set<std::tuple<long, long, long>> s;
    for (const Eigen::Vector3d& c : b.map().occupiedVoxels())
      s.emplace(std::lround(c.x() * 20), std::lround(c.y() * 20), std::lround(c.z() * 20));
    return s;
  };
  auto iou = [](const std::set<std::tuple<long, long, long>>& a, const std::set<std::tuple<long, long, long>>& b) {
    size_t both = 0;
    for (const auto& k : a) both += b.count(k);
    return double(both) / double(a.size() + b.size() - both);
  };
  const auto full = build(0.0, 11), compact = build(0.01, 11), other_noise = build(0.0, 12);
  EXPECT_LT(compact->storedKeyframeBytes() * 1.9, full->storedKeyframeBytes());  // 6 vs 12 bytes a point
  const auto a = keys(*full), b = keys(*compact), c = keys(*other_noise);
  ASSERT_GT(a.size(), 2000u);
  const double quantised = iou(a, b), noise = iou(a, c);
  std::printf("occupied voxels: full %zu, compact %zu, other noise %zu; IoU quantised/full %.4f, noise/noise %.4f\n",
              a.size(), b.size(), c.size(), quantised, noise);
  EXPECT_GE(quantised, noise);
  EXPECT_GE(quantised, 0.95);
}

namespace {
// Twelve sweeps into both maps (and colours, with `colour`), each of a quarter of the room,
// turning, so tiles go idle and come back. Returns the most tiles `tiled` had on disk at once.
size_t sweepQuartersOfTheRoom(OccupancyMap& tiled, OccupancyMap& single, bool colour) {
  size_t most_spilled = 0;
  for (int k = 0; k < 12; ++k) {
    const Eigen::Vector3d origin(0.3 * std::cos(0.5 * k), 0.3 * std::sin(0.5 * k), 1.2);
    std::vector<Eigen::Vector3f> sector;
    for (const Eigen::Vector3f& p : boxRoomHits(origin)) {
      const double az = std::atan2(p.y() - origin.y(), p.x() - origin.x()) + M_PI;  // 0 .. 2 pi
      if (std::fmod(az - 1.1 * k + 8 * M_PI, 2 * M_PI) < 0.5 * M_PI) sector.push_back(p);
    }
    for (OccupancyMap* m : {&tiled, &single}) {
      m->setTime(int64_t(k) * 1000000);
      m->insertRays(sector, origin);
      m->evictIdle();
      if (colour) {
        std::vector<std::array<uint8_t, 3>> rgb;
        for (size_t i = 0; i < sector.size(); ++i) rgb.push_back({uint8_t(i % 200), uint8_t(k * 20), 7});
        m->setColours(sector, rgb);
      }
    }
    most_spilled = std::max(most_spilled, tiled.spilledTiles());
  }
  return most_spilled;
}

// Voxel centres in whole centimetres, sorted.
std::vector<std::tuple<long, long, long>> sortedCentimetres(const std::vector<Eigen::Vector3d>& v) {
  std::vector<std::tuple<long, long, long>> out;
  for (const auto& p : v)
    out.emplace_back(std::lround(p.x() * 100), std::lround(p.y() * 100), std::lround(p.z() * 100));
  std::sort(out.begin(), out.end());
  return out;
}

std::unique_ptr<::octomap::AbstractOcTree> readFull(const std::string& bytes) {
  std::istringstream in(bytes);
  return std::unique_ptr<::octomap::AbstractOcTree>(::octomap::AbstractOcTree::read(in));
}

// .ot: read with octomap, written back by octomap byte for byte; every leaf of the single tree has
// its value (and colour) in the tiled one
void expectTheSameFullTree(const OccupancyMap& single, const OccupancyMap& tiled, bool colour) {
  const std::string single_ot = single.fullBytes(), tiled_ot = tiled.fullBytes();
  auto single_tree = readFull(single_ot), tiled_tree = readFull(tiled_ot);
  ASSERT_TRUE(single_tree && tiled_tree);
  for (const auto& [bytes, tree] :
       {std::make_pair(&single_ot, single_tree.get()), std::make_pair(&tiled_ot, tiled_tree.get())}) {
    std::ostringstream again;
    tree->write(again);
    EXPECT_TRUE(again.str() == *bytes) << "colour " << colour << ": octomap does not write back what it read";
  }
  size_t compared = 0;
  if (colour) {
    auto* a = dynamic_cast<::octomap::ColorOcTree*>(single_tree.get());
    auto* b = dynamic_cast<::octomap::ColorOcTree*>(tiled_tree.get());
    ASSERT_TRUE(a && b);
    for (auto it = a->begin_leafs(); it != a->end_leafs(); ++it, ++compared) {
      const ::octomap::ColorOcTreeNode* n = b->search(it.getKey());
      ASSERT_NE(n, nullptr);
      ASSERT_EQ(n->getLogOdds(), it->getLogOdds());
      ASSERT_TRUE(n->getColor() == it->getColor());
    }
    EXPECT_EQ(b->getNumLeafNodes(), a->getNumLeafNodes());  // a colour tree is not pruned
  } else {
    auto* a = dynamic_cast<::octomap::OcTree*>(single_tree.get());
    auto* b = dynamic_cast<::octomap::OcTree*>(tiled_tree.get());
    ASSERT_TRUE(a && b);
    for (auto it = a->begin_leafs(); it != a->end_leafs(); ++it, ++compared) {
      const ::octomap::OcTreeNode* n = b->search(it.getKey());
      ASSERT_NE(n, nullptr);
      ASSERT_EQ(n->getLogOdds(), it->getLogOdds());
    }
    // both are pruned (at different times, and never across tiles): the leaves differ, the
    // voxels they cover do not
    for (auto it = b->begin_leafs(); it != b->end_leafs(); ++it) {
      const ::octomap::OcTreeNode* n = a->search(it.getKey());
      ASSERT_NE(n, nullptr);
      ASSERT_EQ(n->getLogOdds(), it->getLogOdds());
    }
  }
  EXPECT_GT(compared, 10000u);
}

// .bt: octomap reads it and writes it back unchanged; the occupancy of every voxel agrees; the
// message (the resident tiles only) is a valid tree of fewer nodes
void expectTheSameBinaryTree(const OccupancyMap& single, const OccupancyMap& tiled, bool colour) {
  const std::string single_bt = single.binaryBytes(), tiled_bt = tiled.binaryBytes();
  ::octomap::OcTree single_bin(0.1), tiled_bin(0.1);
  {
    std::istringstream a(single_bt), b(tiled_bt);
    ASSERT_TRUE(single_bin.readBinary(a));
    ASSERT_TRUE(tiled_bin.readBinary(b));
    std::ostringstream again;
    tiled_bin.writeBinaryConst(again);
    EXPECT_TRUE(again.str() == tiled_bt) << "colour " << colour;
  }
  for (auto it = single_bin.begin_leafs(); it != single_bin.end_leafs(); ++it) {
    const ::octomap::OcTreeNode* n = tiled_bin.search(it.getCoordinate());
    ASSERT_NE(n, nullptr);
    ASSERT_EQ(tiled_bin.isNodeOccupied(n), single_bin.isNodeOccupied(*it));
  }
  EXPECT_EQ(tiled_bin.getNumLeafNodes(), single_bin.getNumLeafNodes()) << "colour " << colour;
  ::octomap::OcTree resident(0.1);
  std::istringstream r(tiled.binaryBytes(true));
  ASSERT_TRUE(resident.readBinary(r));
  EXPECT_GT(resident.size(), 0u);
  EXPECT_LT(resident.size(), tiled_bin.size());
}

}  // namespace

// A map kept as tiles that go to disk and come back is the one octree a map without tiles is:
// the same occupied voxels, the same log-odds (and colours) in the .ot, the same occupancy in the
// .bt, and both files are what octomap's own reader reads and its writer writes back byte for
// byte. Sweeps cover a quarter of the room each, turning, so tiles go idle and come back.
TEST(OccupancyMap, TilesOnDiskMakeTheSameTree) {
  for (const bool colour : {false, true}) {
    OctomapOptions tiled_options = options(colour), single_options = options(colour);
    tiled_options.tile_size = 0.8;  // 8 voxels
    tiled_options.tile_idle_s = 1.5;
    single_options.tile_size = 0.0;
    OccupancyMap tiled(tiled_options), single(single_options);
    const size_t most_spilled = sweepQuartersOfTheRoom(tiled, single, colour);
    EXPECT_GT(most_spilled, 10u) << "colour " << colour;
    EXPECT_GT(tiled.residentTiles(), 0u);
    EXPECT_EQ(single.spilledTiles(), 0u);
    const auto occupied = sortedCentimetres(single.occupiedVoxels());
    ASSERT_GT(occupied.size(), 1000u);
    EXPECT_EQ(sortedCentimetres(tiled.occupiedVoxels()), occupied);
    ASSERT_NO_FATAL_FAILURE(expectTheSameFullTree(single, tiled, colour));
    ASSERT_NO_FATAL_FAILURE(expectTheSameBinaryTree(single, tiled, colour));
  }
}
