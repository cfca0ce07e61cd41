// The hashed voxel map: k nearest neighbours equal brute force, the downsampling rule, the local
// window, and the scan downsampling.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
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
      case 0: pts.emplace_back(u(rng), u(rng), small(rng)); break;                // floor
      case 1: pts.emplace_back(10.0 + small(rng), u(rng), 0.2 * u(rng)); break;   // wall
      case 2: pts.emplace_back(u(rng), u(rng) * 0.1 + 3.0, 0.2 * u(rng)); break;  // slab
      default: pts.emplace_back(u(rng), u(rng), u(rng)); break;                   // clutter
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

TEST(VoxelMap, KnnEqualsBruteForceAtTheLioDefaults) {
  // The LIO's search (default map, k 5 within 1.5 m), which settles most queries in the voxels
  // within half the radius: also queries on voxel faces, edges and corners, where the two stages'
  // boxes and the settle test meet.
  VoxelMap map;
  map.insert(mapLikePoints(40000, 9));
  const std::vector<Vec3> stored = map.points();
  std::mt19937 rng(10);
  std::uniform_real_distribution<double> u(-11.0, 11.0);
  std::uniform_int_distribution<int> cell(-10, 10);
  for (int i = 0; i < 600; ++i) {
    Vec3 q(u(rng), u(rng), 0.3 * u(rng));
    if (i % 3 == 1) q.x() = cell(rng);                                                    // on a face
    if (i % 3 == 2) q = Vec3(cell(rng), cell(rng), std::round(q.z())) + Vec3(0, 0.5, 0);  // on an edge
    if (i % 6 == 5) q.y() = std::round(q.y());                                            // on a corner
    for (int k : {1, 5}) {
      Vec3 out[32];
      double d2[32];
      const int n = map.knn(q, k, 1.5, out, d2);
      const std::vector<double> bf = bruteForce(stored, q, k, 1.5);
      ASSERT_EQ(n, static_cast<int>(bf.size())) << "query " << q.transpose() << " k " << k;
      for (int j = 0; j < n; ++j) EXPECT_EQ(d2[j], bf[static_cast<size_t>(j)]) << "query " << q.transpose();
    }
  }
}

TEST(VoxelMap, KnnStaysExactWhenTheOccupancyBitsFillUp) {
  // more voxels than the map's occupancy bits (2^16): most bits are set, the index decides
  VoxelMapOptions o;
  o.voxel_size = 0.05;
  o.max_points_per_voxel = 2;
  o.min_point_distance = 0.0;
  VoxelMap map(o);
  auto expectExact = [&](unsigned seed) {
    const std::vector<Vec3> stored = map.points();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-10.0, 10.0);
    int nonempty = 0;
    for (int i = 0; i < 200; ++i) {
      const Vec3 q(u(rng), u(rng), 0.02 * u(rng));  // near the floor
      Vec3 out[5];
      double d2[5];
      const int n = map.knn(q, 5, 0.2, out, d2);
      const std::vector<double> bf = bruteForce(stored, q, 5, 0.2);
      ASSERT_EQ(n, static_cast<int>(bf.size())) << "query " << q.transpose();
      for (int j = 0; j < n; ++j) EXPECT_EQ(d2[j], bf[static_cast<size_t>(j)]);
      nonempty += n > 0;
    }
    EXPECT_GT(nonempty, 100);
  };
  map.insert(mapLikePoints(120000, 11));
  EXPECT_GT(map.numVoxels(), 70000u);
  expectExact(12);
  // cleared and refilled: no bit of the old voxels hides or fakes a new one
  map.clear();
  map.insert(mapLikePoints(20000, 13));
  expectExact(14);
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
  EXPECT_TRUE(map.insert(Vec3(1.05, 0.1, 0.1)));  // next voxel, though close to (0.9, ...)
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
  const auto idx = firstPointPerVoxel(pts, 0.5);
  EXPECT_EQ(idx, (std::vector<size_t>{0, 2, 3}));
  const auto sub = firstPointPerVoxel(pts, std::vector<size_t>{1, 4, 2}, 0.5);
  EXPECT_EQ(sub, (std::vector<size_t>{1, 2}));
  // a voxel met again after others (not only by consecutive points) keeps its first point
  const auto back = firstPointPerVoxel(pts, std::vector<size_t>{0, 2, 1, 3, 4, 0}, 0.5);
  EXPECT_EQ(back, (std::vector<size_t>{0, 2, 3}));
}

namespace {
// A 20 x 20 x 4 m room, and a 2 x 2 x 1.5 m box (a parked car) at x 4..6 that may be there.
double castRoom(const Vec3& o, const Vec3& d, bool with_box) {
  double best = std::numeric_limits<double>::infinity();
  auto plane = [&](int axis, double at) {
    if (std::abs(d[axis]) < 1e-12) return;
    const double t = (at - o[axis]) / d[axis];
    if (t > 0.0) best = std::min(best, t);
  };
  plane(2, 0.0), plane(2, 4.0), plane(0, 10.0), plane(0, -10.0), plane(1, 10.0), plane(1, -10.0);
  if (with_box) {
    const Vec3 lo(4.0, -1.0, 0.0), hi(6.0, 1.0, 1.5);
    double t0 = 0.0, t1 = best;
    for (int a = 0; a < 3; ++a) {
      const double inv = 1.0 / d[a];
      double ta = (lo[a] - o[a]) * inv, tb = (hi[a] - o[a]) * inv;
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta), t1 = std::min(t1, tb);
    }
    if (t0 <= t1) best = std::min(best, t0);
  }
  return best;
}

// One sweep of a 16-beam spinning LiDAR (-15..15 deg, 0.2 deg azimuth steps) from o.
std::vector<Vec3> sweepFrom(const Vec3& o, bool with_box) {
  std::vector<Vec3> pts;
  for (int ring = 0; ring < 16; ++ring) {
    const double el = (-15.0 + 2.0 * ring) * M_PI / 180.0;
    for (int col = 0; col < 1800; ++col) {
      const double az = col * 0.2 * M_PI / 180.0;
      const Vec3 d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      const double t = castRoom(o, d, with_box);
      if (std::isfinite(t) && t < 30.0) pts.push_back(o + t * d);
    }
  }
  return pts;
}

bool onTheBox(const Vec3& p) {
  return p.x() > 3.95 && p.x() < 6.05 && std::abs(p.y()) < 1.05 && p.z() < 1.55 && p.z() > 0.05;
}
}  // namespace

// The box is mapped, then leaves: in the second that follows, beams through where it stood remove
// its points once three sweeps saw through them (none go in the first two sweeps), while the floor,
// walls and ceiling the beams graze or end on stay.
TEST(VoxelMap, PointsSeenThroughInThreeSweepsLeaveTheMap) {
  VoxelMap map;
  const Vec3 start(0.0, 0.3, 1.5);
  map.insert(sweepFrom(start, true));
  map.insert(sweepFrom(start + Vec3(0.2, 0.0, 0.0), true));
  auto count = [&](bool box) {
    size_t n = 0;
    for (const Vec3& p : map.points()) n += onTheBox(p) == box;
    return n;
  };
  const size_t box_points = count(true), static_points = count(false);
  ASSERT_GT(box_points, 30u);  // 0.4 m spacing: a few dozen on the faces the sensor saw

  SeenThroughOptions o;
  o.ray_stride = 1;
  size_t removed = 0;
  std::vector<std::pair<Vec3, std::vector<Vec3>>> sweeps;
  for (int sweep = 0; sweep < 12; ++sweep) {  // a second at 10 Hz
    // the sensor walks on, bobbing: each sweep's rings cross the box's place at other heights
    const Vec3 origin = start + Vec3(0.3 + 0.05 * sweep, -0.03 * sweep, 0.04 * std::sin(1.3 * sweep));
    const std::vector<Vec3> endpoints = sweepFrom(origin, false);
    removed += map.removeSeenThrough(origin, endpoints, o);
    sweeps.emplace_back(origin, endpoints);
    if (sweep < 2) {
      EXPECT_EQ(removed, 0u) << "after sweep " << sweep;
    }
    map.insert(endpoints);
  }
  const size_t box_left = count(true);
  EXPECT_LT(box_left, box_points / 2) << "of " << box_points << " box points";
  // a box point still there was seen through in fewer than three sweeps (brute force over the beams)
  for (const Vec3& p : map.points()) {
    if (!onTheBox(p)) continue;
    int seen_through = 0;
    for (const auto& [origin, endpoints] : sweeps) {
      bool through = false;
      for (size_t e = 0; e < endpoints.size() && !through; ++e) {
        const Vec3 w = endpoints[e] - origin;
        const double range = w.norm(), along = (p - origin).dot(w / range);
        const double reach = range - std::max(o.end_margin, o.end_margin_fraction * range);
        const double radius = o.beam_radius + o.beam_divergence * along;
        through = range > o.min_range && range <= o.max_range && along >= o.min_range && along <= reach &&
                  (p - origin).squaredNorm() - along * along < radius * radius;
      }
      seen_through += through;
    }
    EXPECT_LT(seen_through, o.misses_to_remove) << "box point " << p.transpose() << " stayed";
  }
  // the static points (floor, walls, ceiling) the beams removed: at most 0.5 %
  const size_t static_removed = removed - (box_points - box_left);
  EXPECT_LE(static_removed, static_points / 200) << "of " << static_points;

  // off: nothing is removed
  VoxelMap kept;
  kept.insert(sweepFrom(start, true));
  o.enabled = false;
  EXPECT_EQ(kept.removeSeenThrough(start, sweepFrom(start, false), o), 0u);
}

TEST(VoxelMap, BeamsCastOnSeveralThreadsRemoveTheSamePoints) {
  // The same walk past the box as above, on maps whose beams are cast on 1, 2 and 3 threads: after
  // every sweep the maps hold the same points in the same order, with the same counts removed.
  const Vec3 start(0.0, 0.3, 1.5);
  std::vector<VoxelMap> maps(3);
  for (auto& m : maps) {
    m.insert(sweepFrom(start, true));
    m.insert(sweepFrom(start + Vec3(0.2, 0.0, 0.0), true));
  }
  WorkerThreads two(2), three(3);
  WorkerThreads* threads[3] = {nullptr, &two, &three};
  SeenThroughOptions o;
  o.ray_stride = 1;
  size_t total = 0;
  for (int sweep = 0; sweep < 12; ++sweep) {
    const Vec3 origin = start + Vec3(0.3 + 0.05 * sweep, -0.03 * sweep, 0.04 * std::sin(1.3 * sweep));
    const std::vector<Vec3> endpoints = sweepFrom(origin, false);
    ASSERT_GE(endpoints.size(), 3 * 128u);  // enough beams for every thread to take a share
    size_t removed[3];
    for (int t = 0; t < 3; ++t) {
      removed[t] = maps[t].removeSeenThrough(origin, endpoints, o, threads[t]);
      maps[t].insert(endpoints);
    }
    total += removed[0];
    for (int t = 1; t < 3; ++t) {
      EXPECT_EQ(removed[t], removed[0]) << "sweep " << sweep << ", " << t + 1 << " threads";
      EXPECT_EQ(maps[t].points(), maps[0].points()) << "sweep " << sweep << ", " << t + 1 << " threads";
    }
  }
  EXPECT_GT(total, 15u);  // the box went
}

// A change of world frame (lio's map.on_loop_correction: move): every point moved by T, found
// where T puts it, and still remembering the range it was seen from.
TEST(VoxelMap, TransformMovesThePointsAndKeepsTheirRanges) {
  VoxelMapOptions o;
  o.voxel_size = 1.0;
  o.max_points_per_voxel = 4;
  o.min_point_distance = 0.2;
  o.refresh_range_ratio = 0.5;
  VoxelMap map(o);
  const Vec3 origin(-10.0, 0.0, 0.0);  // every point seen from about 10 m
  std::vector<Vec3> pts;
  for (int i = 0; i < 50; ++i) pts.push_back(Vec3(0.3 * i, 0.7 * (i % 5), 0.45 * (i % 3)));
  ASSERT_EQ(map.insert(pts, origin), pts.size());
  const Pose3 T = se3::fromRotationTranslation(so3::Exp(Vec3(0.01, -0.02, 0.4)), Vec3(3.3, -1.7, 0.25));
  map.transform(T);
  EXPECT_EQ(map.numPoints(), pts.size());
  Vec3 nb[1];
  double d2[1];
  for (const Vec3& p : pts) {
    ASSERT_EQ(map.knn(T * p, 1, 0.5, nb, d2), 1);
    EXPECT_LT(std::sqrt(d2[0]), 1e-5);
  }
  // the ranges came along: a point beside pts[10] (seen from 13 m) seen from 8 m does not replace
  // it (not within half)...
  const Vec3 q = T * pts[10];
  EXPECT_FALSE(map.insert(q + T.linear() * Vec3(0.05, 0, 0), 8.0));
  // ...one seen from a quarter of it does
  EXPECT_TRUE(map.insert(q + T.linear() * Vec3(0.05, 0, 0), 2.0));
}

TEST(VoxelMap, BetterObservedPointsReplaceWorseOnes) {
  VoxelMapOptions o;
  o.voxel_size = 1.0;
  o.max_points_per_voxel = 2;
  o.min_point_distance = 0.2;
  o.refresh_range_ratio = 0.5;
  VoxelMap map(o);
  auto stored = [&] {
    auto p = map.points();
    std::sort(p.begin(), p.end(), [](const Vec3& a, const Vec3& b) { return a.x() < b.x(); });
    return p;
  };
  const Vec3 far_origin(-30.0, 0.0, 0.0);  // seen from 30 m
  EXPECT_EQ(map.insert({Vec3(0.1, 0.5, 0.5)}, far_origin), 1u);
  // 0.1 m from it, seen from 20 m: not better by half, dropped
  EXPECT_EQ(map.insert({Vec3(0.2, 0.5, 0.5)}, Vec3(-19.8, 0.5, 0.5)), 0u);
  EXPECT_EQ(stored().front(), Vec3(0.1, 0.5, 0.5).cast<float>().cast<double>());
  // seen from 10 m (a third of 30): replaces it
  EXPECT_EQ(map.insert({Vec3(0.15, 0.5, 0.5)}, Vec3(-9.85, 0.5, 0.5)), 1u);
  ASSERT_EQ(map.numPoints(), 1u);
  EXPECT_NEAR(stored().front().x(), 0.15, 1e-6);
  // a second point seen from 40 m fills the voxel; a third, seen from 15 m, replaces the point seen
  // from farthest (40 m), not the one seen from 10 m
  EXPECT_EQ(map.insert({Vec3(0.8, 0.5, 0.5)}, Vec3(-39.2, 0.5, 0.5)), 1u);
  EXPECT_EQ(map.insert({Vec3(0.5, 0.9, 0.5)}, Vec3(-14.5, 0.9, 0.5)), 1u);
  ASSERT_EQ(map.numPoints(), 2u);
  EXPECT_NEAR(stored()[0].x(), 0.15, 1e-6);
  EXPECT_NEAR(stored()[1].x(), 0.5, 1e-6);
  // a fourth from 9 m is not within half of either (10 m, 15 m): dropped
  EXPECT_EQ(map.insert({Vec3(0.9, 0.1, 0.1)}, Vec3(-8.1, 0.1, 0.1)), 0u);
  // points inserted without their sensor position count as perfectly observed: never replaced
  VoxelMap rebuilt(o);
  EXPECT_TRUE(rebuilt.insert(Vec3(0.1, 0.5, 0.5)));
  EXPECT_EQ(rebuilt.insert({Vec3(0.15, 0.5, 0.5)}, Vec3(0.14, 0.5, 0.5)), 0u);
  // ratio 0: the first points stay (the map before refreshing existed)
  o.refresh_range_ratio = 0.0;
  VoxelMap first(o);
  EXPECT_EQ(first.insert({Vec3(0.1, 0.5, 0.5)}, far_origin), 1u);
  EXPECT_EQ(first.insert({Vec3(0.15, 0.5, 0.5)}, Vec3(0.14, 0.5, 0.5)), 0u);
  EXPECT_NEAR(first.points().front().x(), 0.1, 1e-6);
}
