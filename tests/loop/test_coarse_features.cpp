// The coarse features in two stages (keypoints, then their FPFH descriptors) and the cheap exact
// test of whether the second will keep any keypoint, which livo-loop runs instead of the
// descriptors for keyframes that are not registered: both against the computation in one piece.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "livo/loop/coarse_features.hpp"
#include "livo/loop/fpfh.hpp"
#include "livo/loop/voxel_grid.hpp"
#include "real_scans.hpp"
#include "synthetic_scenes.hpp"

namespace livo::loop {
namespace {
using namespace livo::loop::testing;

// computeCoarseFeatures as it was before the split, in one piece: the reference.
CoarseFeatures coarseFeaturesInOnePiece(const Points& cloud, const CoarseFeatureOptions& options) {
  const Points points = centroidPerVoxel(cloud, options.voxel_size);
  CoarseFeatures out;
  if (points.empty()) return out;
  const PointTree tree(points);
  const std::vector<Neighbourhood> geometry = analyseNeighbourhoods(points, tree, options.normal_radius);
  std::vector<char> eligible(points.size(), 0);
  Points normals(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    normals[i] = geometry[i].normal;
    eligible[i] = !normals[i].isZero() && std::abs(normals[i].z()) <= options.max_normal_z;
  }
  std::vector<int> keys = issKeypoints(points, geometry, tree, options.keypoints, eligible);
  if (options.max_keypoints > 0 && keys.size() > static_cast<size_t>(options.max_keypoints))
    keys.resize(options.max_keypoints);
  const Features features = computeFpfh(points, normals, tree, options.feature_radius, keys);
  for (size_t k = 0; k < keys.size(); ++k) {
    if (features[k].isZero()) continue;
    out.points.push_back(points[keys[k]]);
    out.descriptors.push_back(quantise(features[k]));
  }
  return out;
}

bool sameFeatures(const CoarseFeatures& a, const CoarseFeatures& b) {
  if (a.points.size() != b.points.size() || a.descriptors.size() != b.descriptors.size()) return false;
  for (size_t k = 0; k < a.points.size(); ++k)
    if (a.points[k] != b.points[k] || a.descriptors[k].bins != b.descriptors[k].bins) return false;
  return true;
}

Points grid(const Vec3& origin, const Vec3& u, const Vec3& v, int nu, int nv, double step) {
  Points out;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) out.push_back(origin + u * (i * step) + v * (j * step));
  return out;
}

Points withNoise(Points points, double sigma, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, sigma);
  for (Vec3& p : points) p += Vec3(n(rng), n(rng), n(rng));
  return points;
}

// A keypoint whose neighbours all lack a normal: a point with five arms of 0.65-0.95 m, each
// more than the normal radius (1 m) from the others, so only the centre has the 3 neighbours a
// normal takes (and the 6 ISS does), with a horizontal normal (the single arm is along y). Each
// point alone in its 0.6 m voxel, so the centroids are the points.
Points star(const Vec3& centre) {
  Points out{centre};
  for (const Vec3& arm : {Vec3(0.9, 0, 0), Vec3(-0.85, 0, 0), Vec3(0, 0, 0.7), Vec3(0, 0, -0.65), Vec3(0, 0.95, 0)})
    out.push_back(centre + arm);
  return out;
}

struct Case {
  std::string name;
  Points cloud;
  CoarseFeatureOptions options;
};

const std::vector<Case>& cases() {
  static const std::vector<Case> all = [] {
    std::vector<Case> out;
    const CoarseFeatureOptions defaults;
    auto add = [&](const std::string& name, const Points& cloud, CoarseFeatureOptions o = CoarseFeatureOptions{}) {
      out.push_back({name, cloud, o});
    };
    add("empty", {});
    add("one point", {Vec3(1, 2, 3)});
    add("two points", {Vec3(0, 0, 0), Vec3(0.9, 0.1, 0.2)});
    const Points wall = grid(Vec3(5, -5, -2), Vec3::UnitY(), Vec3::UnitZ(), 60, 30, 0.17);
    add("vertical plane, exact", wall);
    add("vertical plane, noisy", withNoise(wall, 0.01, 1));
    const Points ground = grid(Vec3(-8, -8, -1.8), Vec3::UnitX(), Vec3::UnitY(), 90, 90, 0.18);
    add("ground, exact", ground);
    add("ground, noisy", withNoise(ground, 0.02, 2));
    Points floor_and_ceiling = withNoise(ground, 0.02, 3);
    for (const Vec3& p : withNoise(ground, 0.02, 4)) floor_and_ceiling.push_back(p + Vec3(0, 0, 4.0));
    add("floor and ceiling", floor_and_ceiling);
    Points tilted = ground;  // 20 deg: normals at |n_z| 0.94, still above max_normal_z
    for (Vec3& p : tilted) p = Eigen::AngleAxisd(0.35, Vec3::UnitX()) * p;
    add("gentle slope", withNoise(tilted, 0.02, 5));
    Points line_x, line_z, line_oblique;
    for (int i = 0; i < 200; ++i) {
      line_x.push_back(Vec3(-10 + 0.1 * i, 2, 0.5));
      line_z.push_back(Vec3(3, 1, -5 + 0.05 * i));
      line_oblique.push_back(Vec3(1, 2, 0.5) * (0.07 * i));
    }
    add("line along x", line_x);
    add("vertical line", line_z);
    add("oblique line", line_oblique);
    add("noisy line", withNoise(line_oblique, 0.03, 6));
    add("star", star(Vec3(0.3, 0.3, 0.3)));
    Points stars;
    for (int k = 0; k < 6; ++k) {
      const Points s = star(Vec3(0.3 + 6.0 * k, 0.3 - 3.0 * k, 0.3));
      stars.insert(stars.end(), s.begin(), s.end());
    }
    add("stars", stars);
    Points star_and_wall = stars;  // a wall far from the stars gives keypoints with pairs
    for (const Vec3& p : withNoise(wall, 0.02, 7)) star_and_wall.push_back(p + Vec3(40, 0, 0));
    add("stars and a wall", star_and_wall);
    // sparse random clouds, from a few points in a box to some density
    std::mt19937 rng(11);
    for (int n : {5, 8, 12, 20, 30, 50, 80, 120, 200, 400, 800}) {
      for (double side : {2.0, 4.0, 8.0}) {
        std::uniform_real_distribution<double> u(-side / 2, side / 2);
        Points cloud;
        for (int i = 0; i < n; ++i) cloud.push_back(Vec3(u(rng), u(rng), u(rng)));
        add("random " + std::to_string(n) + " in " + std::to_string(side) + " m", cloud);
        CoarseFeatureOptions small = defaults;
        small.feature_radius = 0.8;  // neighbourhoods barely larger than the normals'
        small.keypoints.min_neighbours = 3;
        add("random " + std::to_string(n) + " in " + std::to_string(side) + " m, small radii", cloud, small);
      }
    }
    // views of the synthetic scene, as keyframes, and with options at their limits
    const Points scene = makeScene(11);
    for (int k = 0; k < 3; ++k) {
      const Points view = viewFrom(scene, Vec3(4.0 * k, -2.0 * k, 1.8), 0.7 * k, 25, 0.02, 20 + k);
      add("scene view " + std::to_string(k), view);
      CoarseFeatureOptions o = defaults;
      o.max_keypoints = 1;
      add("scene view " + std::to_string(k) + ", one keypoint", view, o);
      o = defaults;
      o.feature_radius = 0.3;  // hardly a neighbour: most keypoints have no pair
      add("scene view " + std::to_string(k) + ", FPFH radius 0.3 m", view, o);
      o = defaults;
      o.max_normal_z = 0.0;
      add("scene view " + std::to_string(k) + ", no normal is horizontal enough", view, o);
      const Points far = viewFrom(scene, Vec3(4.0 * k, -2.0 * k, 1.8), 0.7 * k, 6, 0.02, 30 + k);
      add("scene view " + std::to_string(k) + " within 6 m", far);
    }
    return out;
  }();
  return all;
}

// The two stages give exactly what computing the features in one piece gives (and what
// computeCoarseFeatures gives), degenerate clouds included.
TEST(CoarseFeatures, StagesComposeToTheComputationInOnePiece) {
  for (const Case& c : cases()) {
    const CoarseFeatures reference = coarseFeaturesInOnePiece(c.cloud, c.options);
    const CoarseKeypoints keypoints = detectCoarseKeypoints(c.cloud, c.options);
    EXPECT_TRUE(sameFeatures(describeCoarseKeypoints(keypoints, c.options), reference)) << c.name;
    EXPECT_TRUE(sameFeatures(computeCoarseFeatures(c.cloud, c.options), reference)) << c.name;
    // the keypoint stage outlives a move (the tree refers to points on the heap)
    CoarseKeypoints first = detectCoarseKeypoints(c.cloud, c.options);
    const CoarseKeypoints moved = std::move(first);
    EXPECT_TRUE(sameFeatures(describeCoarseKeypoints(moved, c.options), reference)) << c.name;
  }
}

// The cheap test is exactly whether describing keeps any keypoint, whether the keypoints have
// valid pairs or not; the cases cover both answers, and keypoints that describing drops.
TEST(CoarseFeatures, CheapKeypointCheckEqualsDescribing) {
  int with = 0, without = 0, without_but_keys = 0;
  for (const Case& c : cases()) {
    const CoarseKeypoints keypoints = detectCoarseKeypoints(c.cloud, c.options);
    const bool expected = !coarseFeaturesInOnePiece(c.cloud, c.options).points.empty();
    EXPECT_EQ(anyKeypointDescribable(keypoints, c.options), expected) << c.name;
    (expected ? with : without) += 1;
    without_but_keys += !expected && !keypoints.keys.empty();
  }
  std::printf("[coarse] %d clouds with coarse features, %d without (%d of them with keypoints)\n", with, without,
              without_but_keys);
  EXPECT_GE(with, 20);
  EXPECT_GE(without, 10);
  EXPECT_GE(without_but_keys, 2);
}

// The degenerate cases say what they should: nothing from nothing, from lines or from
// near-horizontal surfaces; keypoints without a valid pair are kept out.
TEST(CoarseFeatures, DegenerateCloudsHaveNoCoarseFeatures) {
  for (const Case& c : cases()) {
    const bool exact_line = c.name.find("line") != std::string::npos && c.name != "noisy line";
    const bool none = c.name == "empty" || c.name == "one point" || c.name == "two points" ||
                      c.name.rfind("ground", 0) == 0 || c.name == "floor and ceiling" || c.name == "gentle slope" ||
                      exact_line || c.name == "star" || c.name == "stars" ||
                      c.name.find("no normal is horizontal") != std::string::npos;
    const CoarseKeypoints keypoints = detectCoarseKeypoints(c.cloud, c.options);
    if (c.name == "stars and a wall") {
      EXPECT_TRUE(anyKeypointDescribable(keypoints, c.options));
    }
    if (!none) continue;
    EXPECT_FALSE(anyKeypointDescribable(keypoints, c.options)) << c.name;
    EXPECT_TRUE(computeCoarseFeatures(c.cloud, c.options).points.empty()) << c.name;
    if (c.name == "star" || c.name == "stars") {
      EXPECT_EQ(keypoints.keys.size(), c.name == "star" ? 1u : 6u) << "the stars' centres are keypoints";
    }
  }
}

// On real keyframes (KITTI 07, 64 beams) too.
TEST(CoarseFeatures, RealKeyframesInStages) {
  const CoarseFeatureOptions o;
  for (int i = 0; i < 2; ++i) {
    char name[96];
    std::snprintf(name, sizeof(name), "%s/lidar/kitti_07_dump/%06d/points.bin", LIVO_SHARED_DATA, i);
    const Points raw = readXyzBin(name);
    ASSERT_GT(raw.size(), 1000u) << name;
    const CoarseFeatures reference = coarseFeaturesInOnePiece(raw, o);
    const CoarseKeypoints keypoints = detectCoarseKeypoints(raw, o);
    EXPECT_TRUE(sameFeatures(describeCoarseKeypoints(keypoints, o), reference)) << name;
    EXPECT_TRUE(anyKeypointDescribable(keypoints, o)) << name;
    EXPECT_GT(reference.size(), 100u) << name;
  }
}

// anyNonZeroFpfh against computeFpfh itself on small random sets (every seventh on a line), with
// normals that are random, zero, or along the axis (on a line: degenerate pairs), and random query
// subsets in random order (so that pairs with a lower index decide some sets, none others).
TEST(Fpfh, AnyNonZeroEqualsComputingTheFeatures) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> kind(0, 9);
  int non_zero = 0, zero = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const int n = 2 + trial % 40;
    const double side = 0.5 + 0.01 * (trial % 300);
    const bool collinear = trial % 7 == 0;
    Points points, normals;
    const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
    for (int i = 0; i < n; ++i) {
      points.push_back(collinear ? axis * (side * u(rng)) : Vec3(u(rng), u(rng), u(rng)) * side);
      const int k = kind(rng);
      if (k == 0)
        normals.push_back(Vec3::Zero());
      else if (collinear || k == 1)
        normals.push_back(k % 2 ? axis : Vec3(-axis));  // on a line: degenerate pairs
      else
        normals.push_back(Vec3(u(rng), u(rng), u(rng)).normalized());
    }
    const PointTree tree(points);
    std::vector<int> at;
    for (int i = 0; i < n; ++i)
      if (kind(rng) < 3) at.push_back(i);
    std::shuffle(at.begin(), at.end(), rng);
    const double radius = 0.2 + 0.02 * (trial % 100);
    const Features f = computeFpfh(points, normals, tree, radius, at);
    const bool expected = std::any_of(f.begin(), f.end(), [](const Fpfh& x) { return !x.isZero(); });
    ASSERT_EQ(anyNonZeroFpfh(points, normals, tree, radius, at), expected) << "trial " << trial;
    (expected ? non_zero : zero) += 1;
  }
  std::printf("[fpfh] %d sets with a non-zero feature, %d without\n", non_zero, zero);
  EXPECT_GT(non_zero, 500);
  EXPECT_GT(zero, 500);
}

}  // namespace
}  // namespace livo::loop
