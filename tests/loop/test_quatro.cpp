#include <random>

#include <gtest/gtest.h>

#include "livo/loop/coarse_features.hpp"
#include "livo/loop/feature_matching.hpp"
#include "livo/loop/quatro.hpp"
#include "livo/loop/voxel_grid.hpp"
#include "synthetic_scenes.hpp"

namespace livo::loop {
namespace {
using namespace livo::loop::testing;

// Source points, their images under T with noise, and correspondences of which `outlier_ratio`
// are replaced by random target indices.
struct Matched {
  Points source, target;
  Correspondences matches;
};
Matched makeMatched(const Pose3& T, int n, double outlier_ratio, double noise, uint32_t seed) {
  std::mt19937 rng(seed);
  const Points scene = centroidPerVoxel(makeScene(seed), 0.5);
  Matched m;
  std::uniform_int_distribution<size_t> pick(0, scene.size() - 1);
  std::normal_distribution<double> nd(0, noise);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < n; ++i) {
    m.source.push_back(scene[pick(rng)]);
    m.target.push_back(T * m.source.back() + Vec3(nd(rng), nd(rng), nd(rng)));
  }
  std::uniform_int_distribution<int> any(0, n - 1);
  for (int i = 0; i < n; ++i) m.matches.push_back({i, u(rng) < outlier_ratio ? any(rng) : i});
  return m;
}

TEST(Quatro, RecoversYawFromAnyStartWithSeventyPercentOutliers) {
  for (int deg = -180; deg < 180; deg += 30) {
    const Pose3 T = yawPose(deg * M_PI / 180.0, Vec3(4.0, -7.0, 0.3));
    const Matched m = makeMatched(T, 300, 0.7, 0.02, 5 + deg + 180);
    QuatroOptions o;
    o.noise_bound = 0.1;
    const QuatroResult r = quatroRegister(m.source, m.target, m.matches, o);
    ASSERT_TRUE(r.valid) << deg;
    EXPECT_LT(rotationErrorDeg(r.T_target_source, T), 0.5) << deg;
    EXPECT_LT(translationError(r.T_target_source, T), 0.05) << deg;
    int inliers = 0;
    for (const Correspondence& c : m.matches) inliers += c.source == c.target;
    EXPECT_GE(r.num_clique, inliers) << deg;
  }
}

TEST(Quatro, FullSo3VariantHandlesRollAndPitch) {
  Pose3 T = yawPose(2.5, Vec3(-3, 2, 1));
  T.linear() = T.linear() * Eigen::AngleAxisd(0.3, Vec3::UnitX()).toRotationMatrix() *
               Eigen::AngleAxisd(-0.2, Vec3::UnitY()).toRotationMatrix();
  const Matched m = makeMatched(T, 300, 0.6, 0.02, 17);
  QuatroOptions o;
  o.noise_bound = 0.1;
  o.quasi_so3 = false;
  const QuatroResult r = quatroRegister(m.source, m.target, m.matches, o);
  ASSERT_TRUE(r.valid);
  EXPECT_LT(rotationErrorDeg(r.T_target_source, T), 0.5);
  EXPECT_LT(translationError(r.T_target_source, T), 0.05);
}

TEST(Quatro, AdaptiveVotingFindsTheConsensus) {
  std::vector<double> v{2.01, 1.98, 2.03, 2.0, 1.97, 2.02, -5.0, 7.5, 13.0, 0.4, 2.04};
  EXPECT_NEAR(adaptiveVoting(v, 0.1), 2.007, 0.01);
  EXPECT_DOUBLE_EQ(adaptiveVoting({}, 0.1), 0.0);
}

TEST(Quatro, TooFewCorrespondencesIsInvalid) {
  const Points p{{0, 0, 0}, {1, 0, 0}};
  EXPECT_FALSE(quatroRegister(p, p, {{0, 0}, {1, 1}}, {}).valid);
  EXPECT_FALSE(quatroRegister({}, {}, {}, {}).valid);
}

// The whole coarse stage on overlapping views of the synthetic scene: FPFH, mutual matching,
// max clique, quasi-SO(3) GNC-TLS and COTE.
TEST(Quatro, FpfhPipelineRegistersOverlappingViews) {
  const Points scene = makeScene(21);
  for (double yaw : {0.0, 1.2, 2.8, -2.0}) {
    const Pose3 W_T_t = yawPose(0.3, Vec3(0, 0, 1.8));
    const Pose3 W_T_s = yawPose(0.3 + yaw, Vec3(3.0, -2.0, 1.8));
    const CoarseFeatures target = computeCoarseFeatures(viewFrom(scene, W_T_t.translation(), 0.3, 25, 0.02, 1), {});
    const CoarseFeatures source =
        computeCoarseFeatures(viewFrom(scene, W_T_s.translation(), 0.3 + yaw, 25, 0.02, 2), {});
    const Correspondences m = matchDescriptors(source.descriptors, target.descriptors);
    QuatroOptions o;
    o.noise_bound = 0.3;
    const QuatroResult r = quatroRegister(source.points, target.points, m, o);
    const Pose3 truth = W_T_t.inverse() * W_T_s;
    ASSERT_TRUE(r.valid) << yaw;
    EXPECT_LT(rotationErrorDeg(r.T_target_source, truth), 2.0) << yaw;
    EXPECT_LT(translationError(r.T_target_source, truth), 0.3) << yaw;
  }
}

}  // namespace
}  // namespace livo::loop
