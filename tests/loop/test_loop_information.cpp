// A loop edge's covariance from its fine registration: it predicts the spread of the registration
// error over noise draws, it is small only where the surfaces constrain the pose (not along a
// corridor), and it is expressed in the pose graph's edge convention.
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include "livo/loop/gicp.hpp"
#include "livo/loop/loop_information.hpp"
#include "livo/loop/voxel_grid.hpp"
#include "synthetic_scenes.hpp"

namespace livo::loop {
namespace {
using namespace livo::loop::testing;

// The error of an estimate as the right perturbation of the truth: est = truth Exp(e).
Vec6 rightError(const Pose3& truth, const Pose3& est) {
  Vec6 e;
  e.head<3>() = so3::Log(Mat3(truth.linear().transpose() * est.linear()));
  e.tail<3>() = truth.linear().transpose() * (est.translation() - truth.translation());
  return e;
}

// No floor and no cap: the registration's own statistical claim.
LoopInformationOptions unbounded() {
  LoopInformationOptions o;
  o.min_rotation_sigma = o.min_translation_sigma = 1e-12;
  o.max_rotation_sigma = o.max_translation_sigma = 1e6;
  o.roll_pitch_sigma = 0.0;  // what the registration supports, nothing added
  return o;
}

// Two views 4.3 m and 46 deg apart of the synthetic outdoor scene, with fresh point noise every
// draw (1 cm and 3 cm: a survey-grade and a VLP-16-like range noise). Over 40 draws the empirical
// covariance of the registration error (about its mean) against the predicted one: the mean
// normalised squared error (6 for a calibrated covariance) and the per-axis standard deviations.
// With 40 draws a standard deviation is known to 1/sqrt(80) = 11 %, so a predicted deviation
// no more than a factor 1.6 below the empirical one on any axis is no overconfident claim. It may
// be up to 2.5 times above it: the residual variance the covariance is scaled by holds the
// surfaces' sampling (the scene's 0.1-0.3 m grid through 0.4 m voxels) as well as the noise; the
// same in every draw here, so it makes no spread, but a revisit samples the place anew. At 1 cm of
// noise the sampling is half the residual (predicted 1.7-2.3 times the spread), at 3 cm the noise
// dominates (0.9-1.5). NEES accordingly in [6 / 2.5^2, 6 * 1.6^2].
TEST(LoopInformation, CovariancePredictsTheSpreadOfTheRegistrationError) {
  const Points scene = makeScene(31);
  const Pose3 W_T_t = yawPose(0.1, Vec3(0, 0, 1.8));
  const Pose3 W_T_s = yawPose(0.9, Vec3(4.0, 1.5, 1.8));
  const Pose3 truth = W_T_t.inverse() * W_T_s;
  for (const double noise : {0.01, 0.03}) {
    const int draws = 40;
    std::vector<Vec6> errors;
    Mat6 predicted = Mat6::Zero();
    for (int k = 0; k < draws; ++k) {
      const GicpCloud target =
          GicpCloud::build(centroidPerVoxel(viewFrom(scene, W_T_t.translation(), 0.1, 25, noise, 1000 + 2 * k), 0.4));
      const GicpCloud source =
          GicpCloud::build(centroidPerVoxel(viewFrom(scene, W_T_s.translation(), 0.9, 25, noise, 1001 + 2 * k), 0.4));
      Pose3 init = truth;
      init.translation() += Vec3(0.1, -0.05, 0.02);
      const GicpResult r = gicpRegister(source, target, init, {});
      ASSERT_TRUE(r.converged);
      errors.push_back(rightError(truth, r.T_target_source));
      predicted += registrationCovariance(r, r.T_target_source, unbounded()) / draws;
    }
    Vec6 mean = Vec6::Zero();
    for (const Vec6& e : errors) mean += e / draws;
    Mat6 empirical = Mat6::Zero();
    for (const Vec6& e : errors) empirical += (e - mean) * (e - mean).transpose() / (draws - 1);
    double nees = 0.0;
    const Mat6 info = predicted.inverse();
    for (const Vec6& e : errors) nees += (e - mean).dot(info * (e - mean)) / draws;
    std::printf("[loop-information] noise %.2f m: NEES %.2f (6 if calibrated); sd predicted / empirical:", noise, nees);
    for (int i = 0; i < 6; ++i) {
      const double p = std::sqrt(predicted(i, i)), m = std::sqrt(empirical(i, i));
      std::printf(" %.2g/%.2g%s", i < 3 ? p * 180 / M_PI : p, i < 3 ? m * 180 / M_PI : m, i < 3 ? "deg" : "m");
      EXPECT_LT(p / m, 2.5) << "axis " << i << " noise " << noise;
      EXPECT_GT(p / m, 1 / 1.6) << "axis " << i << " noise " << noise;
    }
    std::printf("; bias %.3f deg %.4f m\n", mean.head<3>().norm() * 180 / M_PI, mean.tail<3>().norm());
    EXPECT_GT(nees, 6.0 / (2.5 * 2.5));
    EXPECT_LT(nees, 6.0 * 1.6 * 1.6);
  }
}

// The corridor (synthetic_scenes.hpp, 3 x 3 m, seen from x = 0 and x = 5): the point-to-plane information
// leaves the axis unconstrained, so the edge keeps only the cap's information along it, while the
// across-axis directions are as precise as the walls make them. The GICP Hessian itself, scaled by
// the same residual variance, would claim millimetres along the axis from its in-plane
// regularisation terms.
TEST(LoopInformation, CorridorAxisKeepsOnlyTheCapsInformation) {
  const GicpCloud target = GicpCloud::build(centroidPerVoxel(corridorView(0.0, 1), 0.4));
  const GicpCloud source = GicpCloud::build(centroidPerVoxel(corridorView(5.0, 2), 0.4));
  Pose3 truth = Pose3::Identity();
  truth.translation() = Vec3(5.0, 0, 0);
  const GicpResult r = gicpRegister(source, target, truth, {});
  ASSERT_TRUE(r.converged);
  LoopInformationOptions o;
  o.roll_pitch_sigma = 0.0;  // the registration's own
  const Mat6 cov = registrationCovariance(r, r.T_target_source, o);
  const double along = std::sqrt(cov(3, 3));
  const double across = std::max(std::sqrt(cov(4, 4)), std::sqrt(cov(5, 5)));
  const double naive_along = std::sqrt(r.plane_residual_variance / r.information(3, 3));
  std::printf(
      "[loop-information] corridor: sd along the axis %.3f m (cap %.1f m), across %.4f m; the scaled GICP "
      "Hessian would claim %.4f m along it\n",
      along, o.max_translation_sigma, across, naive_along);
  EXPECT_GT(along, 0.9 * o.max_translation_sigma);
  EXPECT_LT(across, 2 * o.min_translation_sigma);
  EXPECT_LT(naive_along, 0.01);  // what not to trust
  // the rotations are constrained by the walls, floor and ceiling
  for (int i = 0; i < 3; ++i) EXPECT_LT(std::sqrt(cov(i, i)), 2 * o.min_rotation_sigma) << i;
}

// A registration far surer than any floor: what the floors and the added terms leave.
GicpResult confidentRegistration(double fitness = 0.0) {
  GicpResult sure;
  sure.plane_information = Mat6::Identity() * 1e16;
  sure.plane_correspondences = 1000;
  sure.plane_residual_variance = 1e-4;
  sure.fitness = fitness;
  return sure;
}

// Floors and caps: an empty registration (no information) gets the caps (plus the floors), an
// absurdly confident one the floors.
TEST(LoopInformation, FloorsAndCapsBoundEveryAxis) {
  LoopInformationOptions o;
  o.roll_pitch_sigma = 0.0;  // below
  GicpResult none;
  const Mat6 capped = registrationCovariance(none, Pose3::Identity(), o);
  for (int i = 0; i < 6; ++i) {
    const double cap = i < 3 ? o.max_rotation_sigma : o.max_translation_sigma;
    const double floor = i < 3 ? o.min_rotation_sigma : o.min_translation_sigma;
    EXPECT_NEAR(std::sqrt(capped(i, i)), std::hypot(cap, floor), 1e-9) << i;
  }
  const GicpResult sure = confidentRegistration();
  const Pose3 T = yawPose(0.7, Vec3(3, -2, 0.5));
  const Mat6 floored = registrationCovariance(sure, T, o);
  for (int i = 0; i < 6; ++i) {
    const double floor = i < 3 ? o.min_rotation_sigma : o.min_translation_sigma;
    EXPECT_NEAR(std::sqrt(floored(i, i)), floor, 1e-3 * floor) << i;
  }
}

// loop_roll_pitch_sigma: roll and pitch (the levelled frame's x and y rotations) widened by it in
// quadrature; yaw and the translation unchanged.
TEST(LoopInformation, RollAndPitchWidenedYawKept) {
  const GicpResult sure = confidentRegistration();
  const Pose3 T = yawPose(0.7, Vec3(3, -2, 0.5));
  LoopInformationOptions o;
  o.roll_pitch_sigma = 0.0;
  const Mat6 without = registrationCovariance(sure, T, o);
  o.roll_pitch_sigma = 0.02;
  const Mat6 with = registrationCovariance(sure, T, o);
  EXPECT_NEAR(with(0, 0) - without(0, 0), 4e-4, 1e-15);
  EXPECT_NEAR(with(1, 1) - without(1, 1), 4e-4, 1e-15);
  Mat6 rest = with - without;
  rest(0, 0) = rest(1, 1) = 0.0;
  EXPECT_LT(rest.norm(), 1e-15);
}

// loop_fitness_rotation_sigma: a rotation standard deviation in proportion to the fine fitness,
// added in quadrature per axis to what the registration and the floor give; translations unchanged.
TEST(LoopInformation, FitnessWidensTheRotationOnly) {
  const GicpResult sure = confidentRegistration(0.14);  // m^2
  const Pose3 T = yawPose(0.7, Vec3(3, -2, 0.5));
  LoopInformationOptions o;
  o.fitness_rotation_sigma = 0.0;
  const Mat6 without = registrationCovariance(sure, T, o);
  o.fitness_rotation_sigma = 0.036;
  const Mat6 with = registrationCovariance(sure, T, o);
  const double added = 0.036 * 0.14;  // 5.0e-3 rad, 0.29 deg
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(with(i, i) - without(i, i), added * added, 1e-12) << i;
  EXPECT_LT((with.bottomRightCorner<3, 3>() - without.bottomRightCorner<3, 3>()).norm(), 1e-15);
  EXPECT_LT((with.topRightCorner<3, 3>() - without.topRightCorner<3, 3>()).norm(), 1e-15);
}

// The edge convention: the pose graph's residual [Log(R_m^T R); t - t_m] of T Exp(xi) around
// T = T_m is B xi with B = diag(I, R) to first order, so cov_edge = B cov_right B^T.
TEST(LoopInformation, EdgeConventionMatchesThePoseGraphResidual) {
  Pose3 T = yawPose(0.8, Vec3(2, -1, 0.3));
  T.linear() = T.linear() * so3::Exp(Vec3(0.1, -0.2, 0.05));
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1e-4);
  const Mat6 cov_right = Mat6::Identity();
  const Mat6 cov_edge = edgeCovarianceFromRight(T, cov_right);
  for (int k = 0; k < 5; ++k) {
    Vec6 xi;
    for (int i = 0; i < 6; ++i) xi(i) = n(rng);
    const Pose3 Tp = T * se3::Exp(xi);
    Vec6 residual;
    residual << so3::Log(Mat3(T.linear().transpose() * Tp.linear())), Tp.translation() - T.translation();
    Vec6 expected;
    expected << xi.head<3>(), T.linear() * xi.tail<3>();
    EXPECT_LT((residual - expected).norm(), 1e-7);
  }
  EXPECT_TRUE(rightCovarianceFromEdge(T, cov_edge).isApprox(cov_right, 1e-12));
}

// composedCovariance and inverseCovariance against sampling: 4,000 draws of T1 Exp(a) T2 Exp(b)
// and of (T1 Exp(a))^-1, their right-perturbation errors' covariance within 10 % (a variance from
// 4,000 draws is known to 2.2 %).
TEST(LoopInformation, ComposedAndInvertedCovariancesMatchSampling) {
  const Pose3 T1 = yawPose(0.8, Vec3(2, -1, 0.3)), T2 = yawPose(-0.4, Vec3(10, 4, 0));
  Vec6 s1, s2;
  s1 << 0.01, 0.02, 0.005, 0.05, 0.02, 0.1;
  s2 << 0.003, 0.003, 0.02, 0.2, 0.01, 0.03;
  const Mat6 c1 = s1.cwiseAbs2().asDiagonal(), c2 = s2.cwiseAbs2().asDiagonal();
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  const int draws = 4000;
  Mat6 composed = Mat6::Zero(), inverted = Mat6::Zero();
  for (int k = 0; k < draws; ++k) {
    Vec6 a, b;
    for (int i = 0; i < 6; ++i) a(i) = s1(i) * n(rng), b(i) = s2(i) * n(rng);
    const Vec6 ec = se3::Log((T1 * T2).inverse() * (T1 * se3::Exp(a) * T2 * se3::Exp(b)));
    const Vec6 ei = se3::Log(T1 * (T1 * se3::Exp(a)).inverse());
    composed += ec * ec.transpose() / draws;
    inverted += ei * ei.transpose() / draws;
  }
  const Mat6 pc = composedCovariance(c1, T2, c2), pi = inverseCovariance(T1, c1);
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(composed(i, i) / pc(i, i), 1.0, 0.1) << i;
    EXPECT_NEAR(inverted(i, i) / pi(i, i), 1.0, 0.1) << i;
  }
}

}  // namespace
}  // namespace livo::loop
