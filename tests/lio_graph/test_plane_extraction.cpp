// Adaptive plane extraction against planted planes with noise and outliers: recall, precision and
// normal error; the normal-consistency check and the ground-direction constraint each refusing what
// they are meant to refuse.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "livo/lio_graph/plane_extraction.hpp"

using namespace livo;
using namespace livo::lio_graph;

namespace {

struct Planted {
  Plane plane;
  std::vector<int> ids;
};

/// Points on a rectangle (centre c, in-plane axes a and b of half sizes ha and hb), noisy along n.
void addRectangle(const Vec3& c, const Vec3& a, const Vec3& b, double ha, double hb, double noise, int count,
                  std::mt19937& rng, std::vector<Vec3>* pts, std::vector<Planted>* planted) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> g(0.0, noise);
  const Vec3 n = a.cross(b).normalized();
  Planted p;
  p.plane.normal = n;
  p.plane.offset = -n.dot(c);
  for (int i = 0; i < count; ++i) {
    p.ids.push_back(static_cast<int>(pts->size()));
    pts->push_back(c + u(rng) * ha * a + u(rng) * hb * b + g(rng) * n);
  }
  planted->push_back(p);
}

double normalErrorDeg(const Vec3& a, const Vec3& b) {
  return std::acos(std::min(1.0, std::abs(a.dot(b)))) * 180.0 / M_PI;
}

}  // namespace

TEST(PlaneExtraction, FindsPlantedPlanesAmongOutliers) {
  // a room corner seen from the sensor at the origin: floor 1.6 m below, two walls, a far wall at
  // 25 m (noisier: 3 cm), and 20 % uniform clutter
  for (uint32_t seed : {1u, 2u, 3u}) {
    std::mt19937 rng(seed);
    std::vector<Vec3> pts;
    std::vector<Planted> planted;
    addRectangle(Vec3(4, 0, -1.6), Vec3::UnitX(), Vec3::UnitY(), 4, 4, 0.01, 1500, rng, &pts, &planted);
    addRectangle(Vec3(4, 5, 0), Vec3::UnitX(), Vec3::UnitZ(), 4, 1.5, 0.01, 800, rng, &pts, &planted);
    addRectangle(Vec3(8, 0, 0), Vec3::UnitY(), Vec3::UnitZ(), 4, 1.5, 0.01, 800, rng, &pts, &planted);
    addRectangle(Vec3(25, 10, 2), Vec3::UnitY(), Vec3::UnitZ(), 6, 3, 0.03, 600, rng, &pts, &planted);
    const size_t on_planes = pts.size();
    std::uniform_real_distribution<double> box(-2.0, 12.0);
    for (size_t i = 0; i < on_planes / 5; ++i) pts.emplace_back(box(rng), box(rng) - 5.0, box(rng) / 4.0);

    PlaneExtractionOptions o;
    o.seed = seed;
    PlaneExtractionStats stats;
    const std::vector<ExtractedPlane> found = extractPlanes(pts, o, &stats);
    ASSERT_GE(found.size(), planted.size()) << "seed " << seed;
    for (const Planted& p : planted) {
      // the extracted plane with the most of this plane's points
      const ExtractedPlane* best = nullptr;
      int best_hits = 0;
      for (const ExtractedPlane& e : found) {
        int hits = 0;
        for (int i : e.inliers) hits += std::find(p.ids.begin(), p.ids.end(), i) != p.ids.end();
        if (hits > best_hits) best_hits = hits, best = &e;
      }
      ASSERT_NE(best, nullptr);
      const double recall = static_cast<double>(best_hits) / static_cast<double>(p.ids.size());
      const double precision = static_cast<double>(best_hits) / static_cast<double>(best->inliers.size());
      EXPECT_GT(recall, 0.85) << "seed " << seed << " plane offset " << p.plane.offset;
      EXPECT_GT(precision, 0.95) << "seed " << seed << " plane offset " << p.plane.offset;
      EXPECT_LT(normalErrorDeg(best->plane.normal, p.plane.normal), 1.0) << "seed " << seed;
      EXPECT_GE(best->plane.offset, 0.0);  // the sensor on the positive side
      EXPECT_LE(best->quality, o.max_quality_ratio * best->threshold);
    }
    // the floor is the ground, nothing else is
    int grounds = 0;
    for (const ExtractedPlane& e : found) grounds += e.ground;
    EXPECT_EQ(grounds, 1) << "seed " << seed;
  }
}

TEST(PlaneExtraction, ThresholdGrowsWithTheCentroidsRange) {
  PlaneExtractionOptions o;
  EXPECT_DOUBLE_EQ(adaptiveThreshold(Vec3::Zero(), o), o.threshold_min);
  const double near = adaptiveThreshold(Vec3(5, 0, 0), o), far = adaptiveThreshold(Vec3(30, 0, 0), o);
  EXPECT_NEAR(near, o.threshold_base + 5 * o.threshold_per_metre, 1e-12);
  EXPECT_NEAR(far, o.threshold_base + 30 * o.threshold_per_metre, 1e-12);
  EXPECT_DOUBLE_EQ(adaptiveThreshold(Vec3(500, 0, 0), o), o.threshold_max);
}

TEST(PlaneExtraction, TiltedGroundIsRefused) {
  // a ramp 12 degrees steep below the sensor: a ground candidate, but not level enough
  std::mt19937 rng(7);
  std::vector<Vec3> pts;
  std::vector<Planted> planted;
  const double a = 12.0 * M_PI / 180.0;
  addRectangle(Vec3(5, 0, -1.5), Vec3(std::cos(a), 0, std::sin(a)), Vec3::UnitY(), 4, 4, 0.01, 1500, rng, &pts,
               &planted);
  PlaneExtractionOptions o;
  PlaneExtractionStats stats;
  const auto found = extractPlanes(pts, o, &stats);
  EXPECT_TRUE(found.empty());
  EXPECT_EQ(stats.refused_ground_tilt, 1);
  // within the tilt it is the ground
  o.ground_max_tilt_deg = 15.0;
  const auto level = extractPlanes(pts, o, &stats);
  ASSERT_EQ(level.size(), 1u);
  EXPECT_TRUE(level[0].ground);
}

TEST(PlaneExtraction, PointsWhoseLocalNormalsDisagreeDoNotMakeAPlane) {
  // a thick slab of clutter (a hedge, 0.3 m deep, seen from 4 m): within a distance threshold of
  // some plane, but its local normals point everywhere
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> pts;
  for (int i = 0; i < 2000; ++i) pts.emplace_back(4.0 + 0.3 * u(rng), -3.0 + 6.0 * u(rng), -1.0 + 2.0 * u(rng));
  PlaneExtractionOptions o;
  o.threshold_min = o.threshold_max = 0.15;  // wide enough for the slab to look planar by distance
  PlaneExtractionStats stats;
  const auto found = extractPlanes(pts, o, &stats);
  EXPECT_TRUE(found.empty());
  EXPECT_GE(stats.refused_inconsistent, 1);
  // without the check the slab is taken for a wall
  o.min_consistent_fraction = 0.0;
  o.normal_max_angle_deg = 90.0;
  o.max_quality_ratio = 1.0;  // the slab's mean distance is half its depth: at the quality bound
  EXPECT_FALSE(extractPlanes(pts, o).empty());
}

TEST(PlaneExtraction, DeterministicForASeed) {
  std::mt19937 rng(11);
  std::vector<Vec3> pts;
  std::vector<Planted> planted;
  addRectangle(Vec3(3, 0, -1.2), Vec3::UnitX(), Vec3::UnitY(), 3, 3, 0.02, 1000, rng, &pts, &planted);
  addRectangle(Vec3(6, 0, 0), Vec3::UnitY(), Vec3::UnitZ(), 3, 1, 0.02, 600, rng, &pts, &planted);
  const auto a = extractPlanes(pts, PlaneExtractionOptions{});
  const auto b = extractPlanes(pts, PlaneExtractionOptions{});
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].inliers, b[i].inliers);
    EXPECT_EQ(a[i].plane.offset, b[i].plane.offset);
  }
}
