// The hashed voxel map: k nearest neighbours equal brute force, the downsampling rule, the local
// window, and the scan downsampling.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "livo/lio/voxel_map.hpp"

using namespace livo;
using namespace livo::lio;

namespace {
// Points on a few planes and in a cloud, as a LiDAR map looks.
std::vector<Vec3> mapLikePoints(size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-10.0, 10.0), small(-0.02, 0.02);
  std::vector<Vec3> pts;
  for (size_t i = 0; i < n; ++i) {
    switch (i % 4) {
      case 0: pts.emplace_back(u(rng), u(rng), small(rng)); break;          // floor
      case 1: pts.emplace_back(10.0 + small(rng), u(rng), 0.2 * u(rng)); break;  // wall
      case 2: pts.emplace_back(u(rng), u(rng) * 0.1 + 3.0, 0.2 * u(rng)); break;  // slab
      default: pts.emplace_back(u(rng), u(rng), u(rng)); break;             // clutter
    }
  }
  return pts;
}

std::vector<double> bruteForce(const std::vector<Vec3>& pts, const Vec3& q, int k, double r) {
  std::vector<double> d;
  for (const auto& p : pts) {
    const double d2 = (p - q).squaredNorm();
    if (d2 <= r * r) d.push_back(d2);
  }
  std::sort(d.begin(), d.end());
  if (static_cast<int>(d.size()) > k) d.resize(static_cast<size_t>(k));
  return d;
}

void expectKnnEqualsBruteForce(const VoxelMap& map, unsigned seed, int queries) {
  const std::vector<Vec3> stored = map.points();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-11.0, 11.0);
  int nonempty = 0;
  for (int i = 0; i < queries; ++i) {
    const Vec3 q(u(rng), u(rng), 0.3 * u(rng));
    for (int k : {1, 5, 8}) {
      for (double r : {0.3, 1.0, 2.5}) {
        Vec3 out[32];
        double d2[32];
        const int n = map.knn(q, k, r, out, d2);
        const std::vector<double> bf = bruteForce(stored, q, k, r);
        ASSERT_EQ(n, static_cast<int>(bf.size())) << "query " << q.transpose() << " k " << k << " r " << r;
        for (int j = 0; j < n; ++j) {
          EXPECT_DOUBLE_EQ(d2[j], bf[static_cast<size_t>(j)]);
          EXPECT_DOUBLE_EQ((out[j] - q).squaredNorm(), d2[j]);  // the returned point is at that distance
        }
        nonempty += n > 0;
      }
    }
  }
  EXPECT_GT(nonempty, queries);  // most searches find something
}
}  // namespace

TEST(VoxelMap, KnnEqualsBruteForce) {
  VoxelMapOptions o;
  o.voxel_size = 1.0;
  o.max_points_per_voxel = 20;
  o.min_point_distance = 0.05;
  VoxelMap map(o);
  map.insert(mapLikePoints(40000, 1));
  EXPECT_GT(map.numPoints(), 10000u);
  expectKnnEqualsBruteForce(map, 2, 300);
}

TEST(VoxelMap, KnnEqualsBruteForceWithSmallVoxels) {
  // search radius larger than the voxel: many voxels per query
  VoxelMapOptions o;
  o.voxel_size = 0.4;
  o.max_points_per_voxel = 5;
  o.min_point_distance = 0.0;
  VoxelMap map(o);
  map.insert(mapLikePoints(20000, 3));
  expectKnnEqualsBruteForce(map, 4, 100);
}

TEST(VoxelMap, DownsamplingRule) {
  VoxelMapOptions o;
  o.voxel_size = 1.0;
  o.max_points_per_voxel = 3;
  o.min_point_distance = 0.2;
  VoxelMap map(o);
  EXPECT_TRUE(map.insert(Vec3(0.1, 0.1, 0.1)));
  EXPECT_FALSE(map.insert(Vec3(0.2, 0.1, 0.1)));  // 0.1 m from a stored point
  EXPECT_TRUE(map.insert(Vec3(0.5, 0.1, 0.1)));
  EXPECT_TRUE(map.insert(Vec3(0.9, 0.9, 0.9)));
  EXPECT_FALSE(map.insert(Vec3(0.1, 0.9, 0.9)));  // voxel full
  EXPECT_TRUE(map.insert(Vec3(1.05, 0.1, 0.1)));   // next voxel, though close to (0.9, ...)
  EXPECT_FALSE(map.insert(Vec3(std::nan(""), 0, 0)));
  EXPECT_EQ(map.numPoints(), 4u);
  EXPECT_EQ(map.numVoxels(), 2u);
  // negative coordinates fall in their own voxels
  EXPECT_TRUE(map.insert(Vec3(-0.1, 0.1, 0.1)));
  EXPECT_EQ(map.numVoxels(), 3u);
}

TEST(VoxelMap, LocalWindowRemovalKeepsSearchExact) {
  VoxelMapOptions o;
  o.min_point_distance = 0.05;
  VoxelMap map(o);
  map.insert(mapLikePoints(40000, 5));
  const size_t before = map.numVoxels();
  const size_t removed = map.removeFarFrom(Vec3(3.0, 0.0, 0.0), 8.0);
  EXPECT_GT(removed, 0u);
  EXPECT_EQ(map.numVoxels(), before - removed);
  for (const auto& p : map.points()) EXPECT_LT((p - Vec3(3.0, 0.0, 0.0)).norm(), 8.0 + std::sqrt(3.0));
  expectKnnEqualsBruteForce(map, 6, 100);
  // inserting again after removal works and stays exact
  map.insert(mapLikePoints(4000, 7));
  expectKnnEqualsBruteForce(map, 8, 50);
  map.clear();
  EXPECT_TRUE(map.empty());
  Vec3 out[5];
  double d2[5];
  EXPECT_EQ(map.knn(Vec3::Zero(), 5, 1.0, out, d2), 0);
}

TEST(VoxelMap, BoundedMemoryOverALongPath) {
  // A sensor driving 2 km in a straight line, pruning every 10 m: the map stays bounded.
  VoxelMap map;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-30.0, 30.0);
  size_t max_voxels_late = 0, voxels_at_500 = 0;
  for (int step = 0; step < 200; ++step) {
    const Vec3 c(10.0 * step, 0.0, 0.0);
    std::vector<Vec3> scan;
    for (int i = 0; i < 3000; ++i) scan.emplace_back(c.x() + u(rng), u(rng), 0.0);
    map.insert(scan);
    map.removeFarFrom(c, 50.0);
    if (step == 50) voxels_at_500 = map.numVoxels();
    if (step > 50) max_voxels_late = std::max(max_voxels_late, map.numVoxels());
  }
  EXPECT_LE(max_voxels_late, voxels_at_500 * 11 / 10);
}

TEST(VoxelMap, ScanDownsamplingKeepsTheFirstPointPerVoxel) {
  const std::vector<Vec3> pts = {Vec3(0.1, 0.1, 0.1), Vec3(0.2, 0.2, 0.2), Vec3(0.6, 0.1, 0.1), Vec3(-0.1, 0, 0),
                                 Vec3(0.3, 0.4, 0.1)};
  const auto idx = voxelDownsample(pts, 0.5);
  EXPECT_EQ(idx, (std::vector<size_t>{0, 2, 3}));
  const auto sub = voxelDownsample(pts, std::vector<size_t>{1, 4, 2}, 0.5);
  EXPECT_EQ(sub, (std::vector<size_t>{1, 2}));
}
