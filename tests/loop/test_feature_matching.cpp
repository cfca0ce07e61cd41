#include <algorithm>
#include <cstdlib>
#include <random>

#include <gtest/gtest.h>

#include "livo/loop/coarse_features.hpp"
#include "livo/loop/feature_matching.hpp"
#include "synthetic_scenes.hpp"

namespace livo::loop {
namespace {
using namespace livo::loop::testing;

Fpfh randomFeature(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0f, 200.0f);
  Fpfh f;
  for (int k = 0; k < kFpfhSize; ++k) f[k] = u(rng);
  return f;
}

int l1(const Descriptor& a, const Descriptor& b) {
  int s = 0;
  for (size_t k = 0; k < a.bins.size(); ++k) s += std::abs(int(a.bins[k]) - int(b.bins[k]));
  return s;
}

// The vectorised distance is the plain L1 distance over all 33 bins (the last one included).
TEST(FeatureMatching, DescriptorDistanceIsL1OverAllBins) {
  std::mt19937 rng(3);
  for (int i = 0; i < 200; ++i) {
    const Descriptor a = quantise(randomFeature(rng)), b = quantise(randomFeature(rng));
    EXPECT_EQ(descriptorDistance(a, b), l1(a, b));
  }
  Fpfh f = Fpfh::Zero(), g = Fpfh::Zero();
  g[kFpfhSize - 1] = 17.4f;
  EXPECT_EQ(descriptorDistance(quantise(f), quantise(g)), 17);
  g[0] = 300.0f;  // saturates
  EXPECT_EQ(quantise(g).bins[0], 255);
}

// Mutual nearest neighbours against brute force: a permuted, slightly perturbed copy of the source
// among distractors matches back to itself; zero descriptors never match.
TEST(FeatureMatching, MutualNearestNeighboursMatchBruteForce) {
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, 2.0f);
  Features source, target;
  for (int i = 0; i < 300; ++i) source.push_back(randomFeature(rng));
  std::vector<int> perm(300);
  for (int i = 0; i < 300; ++i) perm[i] = i;
  std::shuffle(perm.begin(), perm.end(), rng);
  target.resize(450);
  for (int i = 0; i < 300; ++i) {
    Fpfh f = source[i];
    for (int k = 0; k < kFpfhSize; ++k) f[k] = std::clamp(f[k] + noise(rng), 0.0f, 200.0f);
    target[perm[i]] = f;
  }
  for (int j = 300; j < 450; ++j) target[j] = randomFeature(rng);
  source.push_back(Fpfh::Zero());
  target.push_back(Fpfh::Zero());
  const Descriptors s = quantise(source), t = quantise(target);
  const Correspondences m = matchDescriptors(s, t);

  // brute force, lowest index on ties
  auto nearest = [](const Descriptor& q, const Descriptors& set) {
    int best = -1, best_d = 1 << 30;
    for (size_t j = 0; j < set.size(); ++j)
      if (!set[j].isZero() && l1(q, set[j]) < best_d) best_d = l1(q, set[best = static_cast<int>(j)]);
    return best;
  };
  Correspondences expected;
  for (size_t i = 0; i + 1 < s.size(); ++i) {
    const int j = nearest(s[i], t);
    if (nearest(t[j], s) == static_cast<int>(i)) expected.push_back({static_cast<int>(i), j});
  }
  ASSERT_EQ(m.size(), expected.size());
  for (size_t k = 0; k < m.size(); ++k) {
    EXPECT_EQ(m[k].source, expected[k].source);
    EXPECT_EQ(m[k].target, expected[k].target);
  }
  int right = 0;
  for (const Correspondence& c : m) right += c.target == perm[c.source];
  EXPECT_EQ(right, 300);  // every perturbed copy found its source
  for (const Correspondence& c : m) EXPECT_LT(c.source, 300);
}

// ISS keypoints avoid flat ground and sit on structure, and are a small part of the cloud.
TEST(FeatureMatching, KeypointsAreFewAndOffTheGround) {
  const Points scene = makeScene(11);
  const Points view = viewFrom(scene, Vec3(0, 0, 1.8), 0.0, 25, 0.01, 1);
  const CoarseFeatures f = computeCoarseFeatures(view, {});
  ASSERT_GT(f.size(), 50u);
  EXPECT_LE(f.size(), static_cast<size_t>(CoarseFeatureOptions{}.max_keypoints));
  EXPECT_EQ(f.descriptors.size(), f.size());
  int on_ground = 0;
  for (const Vec3& p : f.points) on_ground += p.z() < -1.8 + 0.15 && std::hypot(p.x(), p.y()) < 8.0;
  EXPECT_LT(on_ground, static_cast<int>(f.size()) / 20);
  for (const Descriptor& d : f.descriptors) EXPECT_FALSE(d.isZero());
}

}  // namespace
}  // namespace livo::loop
