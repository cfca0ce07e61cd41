// The voxel planes: the range noise's part taken out of a cell's scatter (a wall crossed by two
// rings keeps its normal, where a plain least-squares fit leans towards the beams), what is not
// a plane (one ring's arc, an edge, too few points), the range refresh and the local window.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "livo/lio/voxel_planes.hpp"

using namespace livo;
using namespace livo::lio;

namespace {
constexpr double kSigma = 0.03;  // m, a VLP-16's range noise

VoxelPlanesOptions options() {
  VoxelPlanesOptions o;
  o.enabled = true;
  o.cell_size = 0.5;
  o.max_points = 100000;
  o.min_points = 50;
  o.point_stride = 1;
  o.range_noise_std = kSigma;
  o.refresh_range_ratio = 0.0;
  return o;
}

/// Points of the surface points `on`, seen from `origin`, each moved along its beam by the range
/// noise.
std::vector<Vec3> seenWithRangeNoise(const std::vector<Vec3>& on, const Vec3& origin, unsigned seed,
                                     double sigma = kSigma) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<Vec3> out;
  for (const Vec3& p : on) out.push_back(p + noise(rng) * (p - origin).normalized());
  return out;
}

/// Two rings across the wall x = 5.25 in the cell [5, 5.5) x [0, 0.5) x [2, 2.5), seen from the
/// origin about 22 degrees below them.
std::vector<Vec3> twoRingsOnWall(int per_ring) {
  std::vector<Vec3> on;
  for (const double z : {2.1, 2.3})
    for (int i = 0; i < per_ring; ++i) on.emplace_back(5.25, 0.01 + 0.48 * i / (per_ring - 1), z);
  return on;
}

double angleDeg(const Vec3& a, const Vec3& b) { return std::acos(std::min(1.0, std::abs(a.dot(b)))) * 180.0 / M_PI; }
}  // namespace

TEST(VoxelPlanes, RangeNoiseDoesNotLeanTheWallTowardsTheBeams) {
  const std::vector<Vec3> pts = seenWithRangeNoise(twoRingsOnWall(3000), Vec3::Zero(), 7);
  VoxelPlanes planes(options());
  planes.add(pts, Vec3::Zero());
  const Plane* plane = planes.planeAt(Vec3(5.25, 0.25, 2.2));
  ASSERT_NE(plane, nullptr);
  // a plain least-squares plane through the same points leans by about
  // sigma^2 sin(e) cos(e) / (in-plane spread)^2 = 1.6 deg here: the scene shows the effect
  PlaneFit plain;
  ASSERT_TRUE(fitPlane(pts.data(), static_cast<int>(pts.size()), &plain));
  EXPECT_GT(angleDeg(plain.plane.normal, Vec3::UnitX()), 1.0);
  EXPECT_LT(angleDeg(plane->normal, Vec3::UnitX()), 0.3);
  EXPECT_NEAR(std::abs(plane->distance(Vec3(5.25, 0.25, 2.2))), 0.0, 0.003);
}

TEST(VoxelPlanes, OneRingIsNotAPlane) {
  // one ring's arc across the floor 2 m below, smeared along its beams: a thin sheet holding the
  // beams, not the floor
  std::vector<Vec3> on;
  for (int i = 0; i < 2000; ++i) on.emplace_back(5.25, 0.01 + 0.48 * i / 1999.0, -2.0 + 1e-3);
  VoxelPlanes planes(options());
  planes.add(seenWithRangeNoise(on, Vec3::Zero(), 11), Vec3::Zero());
  EXPECT_EQ(planes.planeAt(Vec3(5.25, 0.25, -1.99)), nullptr);
  EXPECT_EQ(planes.numPlanes(), 0u);
}

TEST(VoxelPlanes, AnEdgeIsNotAPlane) {
  // floor z = 0.05 meeting the wall x = 0.25 inside one cell, seen from (2, 0.25, 1.5)
  std::vector<Vec3> on;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) {
      const double a = 0.01 + 0.48 * i / 39.0, b = 0.01 + 0.48 * j / 39.0;
      on.emplace_back(a < 0.25 ? 0.25 : a, b, a < 0.25 ? 0.05 + (0.25 - a) * 1.8 : 0.05);
    }
  VoxelPlanes planes(options());
  const Vec3 origin(2.0, 0.25, 1.5);
  planes.add(seenWithRangeNoise(on, origin, 13, 0.005), origin);
  EXPECT_EQ(planes.planeAt(Vec3(0.3, 0.25, 0.05)), nullptr);
}

TEST(VoxelPlanes, FewPointsAreNotAPlane) {
  VoxelPlanesOptions o = options();
  o.min_points = 500;
  VoxelPlanes planes(o);
  const std::vector<Vec3> pts = seenWithRangeNoise(twoRingsOnWall(200), Vec3::Zero(), 17);
  planes.add(pts, Vec3::Zero());
  EXPECT_EQ(planes.planeAt(Vec3(5.25, 0.25, 2.2)), nullptr);
  planes.add(seenWithRangeNoise(twoRingsOnWall(200), Vec3::Zero(), 19), Vec3::Zero());
  EXPECT_NE(planes.planeAt(Vec3(5.25, 0.25, 2.2)), nullptr);
}

TEST(VoxelPlanes, ANearerViewStartsTheCellAgain) {
  VoxelPlanesOptions o = options();
  o.refresh_range_ratio = 0.5;
  VoxelPlanes planes(o);
  // the wall first seen 4 cm off where it is (as a far, smeared view would place it) ...
  std::vector<Vec3> far_view = twoRingsOnWall(2000);
  for (Vec3& p : far_view) p.x() += 0.04;
  const Vec3 far(-20.0, 0.25, 2.2);
  planes.add(seenWithRangeNoise(far_view, far, 23, 0.002), far);
  const Plane* before = planes.planeAt(Vec3(5.25, 0.25, 2.2));
  ASSERT_NE(before, nullptr);
  EXPECT_NEAR(std::abs(before->distance(Vec3(5.25, 0.25, 2.2))), 0.04, 0.003);
  // ... then from less than half the range: the cell keeps only the nearer view
  const Vec3 near(-5.0, 0.25, 2.2);
  planes.add(seenWithRangeNoise(twoRingsOnWall(2000), near, 29, 0.002), near);
  const Plane* after = planes.planeAt(Vec3(5.25, 0.25, 2.2));
  ASSERT_NE(after, nullptr);
  EXPECT_NEAR(after->distance(Vec3(5.25, 0.25, 2.2)), 0.0, 0.002);
  // a farther view again (more than twice the nearest range the cell holds) is not taken
  planes.add(seenWithRangeNoise(far_view, far, 31, 0.002), far);
  EXPECT_NEAR(planes.planeAt(Vec3(5.25, 0.25, 2.2))->distance(Vec3(5.25, 0.25, 2.2)), 0.0, 0.002);
}

TEST(VoxelPlanes, LocalWindowAndClear) {
  VoxelPlanes planes(options());
  planes.add(seenWithRangeNoise(twoRingsOnWall(2000), Vec3::Zero(), 37), Vec3::Zero());
  std::vector<Vec3> other = twoRingsOnWall(2000);
  for (Vec3& p : other) p.y() += 50.0;
  planes.add(seenWithRangeNoise(other, Vec3(0, 50, 0), 41), Vec3(0, 50, 0));
  ASSERT_EQ(planes.numPlanes(), 2u);
  planes.removeFarFrom(Vec3::Zero(), 20.0);
  EXPECT_NE(planes.planeAt(Vec3(5.25, 0.25, 2.2)), nullptr);
  EXPECT_EQ(planes.planeAt(Vec3(5.25, 50.25, 2.2)), nullptr);
  EXPECT_EQ(planes.numCells(), 1u);
  planes.clear();
  EXPECT_EQ(planes.numCells(), 0u);
  EXPECT_EQ(planes.planeAt(Vec3(5.25, 0.25, 2.2)), nullptr);
}

TEST(VoxelPlanes, BadOptionsAndPointsAreRefused) {
  VoxelPlanesOptions o = options();
  o.min_points = 2;
  EXPECT_THROW(VoxelPlanes{o}, std::invalid_argument);
  o = options();
  o.refresh_range_ratio = 1.0;
  EXPECT_THROW(VoxelPlanes{o}, std::invalid_argument);
  VoxelPlanes planes(options());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  planes.add({Vec3(nan, 0, 0), Vec3(1, 1, 1)}, Vec3::Zero());
  EXPECT_EQ(planes.numCells(), 1u);
  EXPECT_EQ(planes.planeAt(Vec3(nan, 0, 0)), nullptr);
}
