// The point-patch map: one point per voxel, a bounded number of patches per point, pruning by
// radius and by count (least recently seen first), loop-correction transform, and memory that
// stops growing on a long walk.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "livo/vio/point_patch_map.hpp"

using namespace livo;
using namespace livo::vio;

namespace {
PatchObservation observation(int64_t utime, uint8_t fill = 100) {
  PatchObservation o;
  o.utime = utime;
  o.view.T_W_I.translation() = Vec3(0.0, 0.0, static_cast<double>(utime) * 1e-6);
  o.view.vel_W = Vec3(1.0, 0.0, 0.0);
  o.view.T_I_C = se3::fromRotationTranslation(so3::Exp(Vec3(-M_PI / 2, 0.0, -M_PI / 2)), Vec3(0.08, 0.0, 0.02));
  o.pixels.assign(3 * kStoredArea, fill);
  return o;
}
}  // namespace

TEST(PointPatchMap, OnePointPerVoxelAndBoundedPatches) {
  MapOptions o;
  o.voxel_size = 0.5;
  o.max_observations = 3;
  PointPatchMap map(o);
  EXPECT_EQ(map.add(Vec3(0.1, 0.1, 0.1), 1, observation(1)), 0);
  EXPECT_EQ(map.add(Vec3(0.4, 0.2, 0.3), 2, observation(2)), -1);  // same voxel
  EXPECT_EQ(map.add(Vec3(-0.1, 0.1, 0.1), 3, observation(3)), 1);  // the neighbour voxel
  EXPECT_EQ(map.find(Vec3(0.45, 0.45, 0.45)), 0);
  EXPECT_EQ(map.find(Vec3(-0.45, 0.45, 0.45)), 1);
  EXPECT_EQ(map.find(Vec3(0.55, 0.45, 0.45)), -1);
  for (int k = 10; k < 15; ++k) map.addObservation(0, observation(k, static_cast<uint8_t>(k)));
  ASSERT_EQ(map.point(0).observations.size(), 3u);
  EXPECT_EQ(map.point(0).observations.front().utime, 12);  // the oldest went first
  EXPECT_EQ(map.point(0).observations.back().level(2)[5], 14);
  EXPECT_EQ(map.observationCount(), 4u);
}

TEST(PointPatchMap, PrunesByRadiusThenLeastRecentlySeen) {
  MapOptions o;
  o.voxel_size = 1.0;
  o.radius = 10.0;
  o.max_points = 5;
  PointPatchMap map(o);
  for (int i = 0; i < 12; ++i) map.add(Vec3(i + 0.5, 0.5, 0.5), 100 + i, observation(100 + i));
  map.point(1).last_seen = 1000;  // seen recently: survives the count bound
  map.prune(Vec3(0.5, 0.5, 0.5));
  // radius: x <= 10.5 keeps points 0..10; count: the most recently seen among them, down to 90 %
  // of the bound (4 of 5)
  ASSERT_EQ(map.size(), 4u);
  std::vector<double> xs;
  for (const auto& m : map.points()) xs.push_back(m.position.x());
  EXPECT_EQ(xs, (std::vector<double>{1.5, 8.5, 9.5, 10.5}));  // in creation order
  // the index follows the compaction
  EXPECT_EQ(map.find(Vec3(9.5, 0.5, 0.5)), 2);
  EXPECT_EQ(map.find(Vec3(0.5, 0.5, 0.5)), -1);
  // within the bound and not moved: nothing changes
  map.add(Vec3(20.5, 0.5, 0.5), 2000, observation(2000));
  map.prune(Vec3(0.6, 0.5, 0.5));
  EXPECT_EQ(map.size(), 5u);
  // moved by more than a tenth of the radius: the far point goes
  map.prune(Vec3(2.0, 0.5, 0.5));
  EXPECT_EQ(map.size(), 4u);
  EXPECT_EQ(map.find(Vec3(20.5, 0.5, 0.5)), -1);
}

TEST(PointPatchMap, TransformMovesPointsAndObservationPoses) {
  MapOptions o;
  PointPatchMap map(o);
  map.add(Vec3(1.0, 2.0, 3.0), 1, observation(1));
  EXPECT_EQ(map.add(Vec3(1.05, 2.0, 3.0), 1, observation(1)), -1);  // the same voxel
  map.add(Vec3(-4.0, 2.0, 3.0), 1, observation(1));
  ASSERT_EQ(map.size(), 2u);
  const Pose3 T = se3::fromRotationTranslation(so3::Exp(Vec3(0.0, 0.0, 0.3)), Vec3(0.5, -1.0, 0.2));
  map.transform(T);
  EXPECT_TRUE(map.point(0).position.isApprox(T * Vec3(1.0, 2.0, 3.0)));
  // the body pose of the view and its motion move with the map; the extrinsic it was cut through does not
  const ReferenceView& v = map.point(0).observations[0].view;
  EXPECT_TRUE(v.T_W_I.isApprox(T * observation(1).view.T_W_I));
  EXPECT_TRUE(v.cameraPose().isApprox(T * observation(1).view.cameraPose()));
  EXPECT_TRUE(v.vel_W.isApprox(T.linear() * Vec3(1.0, 0.0, 0.0)));
  EXPECT_TRUE(v.T_I_C.isApprox(observation(1).view.T_I_C));
  EXPECT_TRUE(map.point(0).observations[0].cameraCentre().isApprox(T * observation(1).cameraCentre()));
  EXPECT_EQ(map.find(T * Vec3(-4.0, 2.0, 3.0)), 1);
}

TEST(PointPatchMap, MemoryIsBoundedOnALongWalk) {
  // 3,000 frames (2.5 min at 20 Hz) of a camera walking 1 m/s along x and adding 60 points per
  // frame around itself, each seen 4 times: the map saturates at its count bound and its memory
  // stops growing.
  MapOptions o;
  o.max_points = 4000;
  o.radius = 30.0;
  o.max_observations = 4;
  PointPatchMap map(o);
  size_t memory_at_1000 = 0;
  uint64_t rng = 12345;
  auto uniform = [&] {
    rng = rng * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(rng >> 11) * (1.0 / 9007199254740992.0);
  };
  for (int f = 0; f < 3000; ++f) {
    const int64_t t = f * 50000;
    const Vec3 c(0.05 * f, 0.0, 1.5);
    for (int k = 0; k < 60; ++k) {
      const Vec3 p = c + Vec3(uniform() * 20.0, uniform() * 20.0 - 10.0, uniform() * 3.0 - 1.5);
      const int i = map.add(p, t, observation(t));
      if (i >= 0)
        for (int j = 0; j < 4; ++j) map.addObservation(i, observation(t + j));
    }
    map.prune(c);
    ASSERT_LE(map.size(), 4000u);
    if (f == 1000) memory_at_1000 = map.memoryBytes();
  }
  EXPECT_GE(map.size(), 3600u);
  EXPECT_LE(map.observationCount(), 4u * 4000u);
  const size_t bytes = map.memoryBytes();
  EXPECT_LE(bytes, memory_at_1000 * 11 / 10);
  // about a patch pyramid per observation: 4000 x 4 x 768 B (16x16 at 3 levels) = 12.3 MB, plus the
  // bookkeeping, mostly each observation's view and pose covariance (sizeof(PatchObservation))
  std::printf("map memory %.2f MB: %zu points, %zu observations of %zu B + %d B of patches\n", bytes * 1e-6, map.size(),
              map.observationCount(), sizeof(PatchObservation), 3 * kStoredArea);
  EXPECT_LT(bytes, 22u * 1000u * 1000u);
  EXPECT_GT(bytes, 4000u * 4u * 3u * kStoredArea);
}
