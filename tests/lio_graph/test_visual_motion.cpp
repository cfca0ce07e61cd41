// The visual subsystem's motion as livo-lio-graph takes it (visual_motion.hpp): relative poses
// interpolated between samples, independent of the visual world's frame, refused out of span,
// across epochs, out of order or non-finite; the relative-pose factor that can carry it into the
// graph (graph_factors.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "livo/graph_factors.hpp"

#include "livo/lio_graph/visual_motion.hpp"

using namespace livo;
using namespace livo::lio_graph;

namespace {

/// A body turning at 0.5 rad/s while moving at 2 m/s along its x, in a visual world V moved by G.
Pose3 bodyAt(double t, const Pose3& G) {
  const Mat3 R = so3::Exp(Vec3(0.0, 0.0, 0.5 * t));
  const Vec3 p(2.0 * std::sin(0.5 * t) / 0.5, 2.0 * (1.0 - std::cos(0.5 * t)) / 0.5, 0.0);
  return G * se3::fromRotationTranslation(R, p);
}

}  // namespace

TEST(VisualMotion, RelativeMotionIsInterpolatedAndFrameFree) {
  const Pose3 G = se3::fromRotationTranslation(so3::Exp(Vec3(0.1, -0.2, 1.0)), Vec3(5.0, -3.0, 2.0));
  VisualMotion vm;
  for (int k = 0; k <= 40; ++k) ASSERT_TRUE(vm.add(VisualSample{1'000'000 + k * 50'000, bodyAt(0.05 * k, G), 0}));
  // between samples (25 ms in): linear interpolation of a 2 m/s arc over 50 ms is good to 0.3 mm
  Pose3 rel;
  ASSERT_TRUE(vm.relative(1'000'000 + 225'000, 1'000'000 + 1'325'000, &rel));
  const Pose3 truth = bodyAt(0.225, Pose3::Identity()).inverse() * bodyAt(1.325, Pose3::Identity());
  EXPECT_LT((rel.translation() - truth.translation()).norm(), 3e-4);
  EXPECT_LT(so3::Log(Mat3(rel.linear().transpose() * truth.linear())).norm(), 1e-9);
  // outside the buffered span
  EXPECT_FALSE(vm.relative(999'000, 1'100'000, &rel));
  EXPECT_FALSE(vm.relative(1'100'000, 3'000'001, &rel));
}

TEST(VisualMotion, RefusesDisorderAndNonFiniteAndStartsAnewWithAnEpoch) {
  VisualMotion vm;
  std::string why;
  ASSERT_TRUE(vm.add(VisualSample{1'000'000, Pose3::Identity(), 0}));
  ASSERT_TRUE(vm.add(VisualSample{1'050'000, Pose3::Identity(), 0}));
  EXPECT_FALSE(vm.add(VisualSample{1'050'000, Pose3::Identity(), 0}, &why));
  EXPECT_NE(why.find("not later"), std::string::npos);
  Pose3 bad = Pose3::Identity();
  bad.translation().x() = std::nan("");
  EXPECT_FALSE(vm.add(VisualSample{1'100'000, bad, 0}, &why));
  // a new epoch (the visual subsystem restarted in a new frame): the old samples go
  ASSERT_TRUE(vm.add(VisualSample{1'100'000, Pose3::Identity(), 1}));
  Pose3 rel;
  EXPECT_FALSE(vm.relative(1'000'000, 1'100'000, &rel));
  EXPECT_EQ(vm.newest(), 1'100'000);
}

namespace {

/// The factor's whitened residual at poses T_i, T_j (and scale s for the scaled factor).
Vec6 residualOf(ceres::CostFunction* f, const Pose3& Ti, const Pose3& Tj, double s = 1.0) {
  const Eigen::Quaterniond qi(Ti.linear()), qj(Tj.linear());
  const Vec3 pi = Ti.translation(), pj = Tj.translation();
  std::vector<const double*> blocks = {qi.coeffs().data(), pi.data(), qj.coeffs().data(), pj.data(), &s};
  Vec6 r;
  f->Evaluate(blocks.data(), r.data(), nullptr);
  return r;
}

}  // namespace

TEST(GraphFactors, RelativePoseFactorMeasuresTheMotionInTheFirstBodyFrame) {
  const Pose3 Ti = se3::fromRotationTranslation(so3::Exp(Vec3(0.1, -0.2, 0.7)), Vec3(1.0, 2.0, 0.5));
  const Pose3 T_i_j = se3::fromRotationTranslation(so3::Exp(Vec3(0.02, 0.01, 0.15)), Vec3(0.4, -0.05, 0.02));
  const Pose3 Tj = Ti * T_i_j;
  Vec6 sigma;
  sigma << 0.01, 0.01, 0.02, 0.05, 0.05, 0.1;
  const Mat6 info = sigma.cwiseInverse().cwiseAbs2().asDiagonal();
  std::unique_ptr<ceres::CostFunction> f(makeRelativePoseFactor(T_i_j, info));
  EXPECT_LT(residualOf(f.get(), Ti, Tj).norm(), 1e-12);
  // a rotation of j on the right by dtheta and a world-frame shift d of j: the error [dtheta,
  // R_i^T d] whitened by the information (any square root of it: compare the squared norms)
  const Vec3 dtheta(0.003, -0.002, 0.004), d(0.02, -0.01, 0.03);
  const Pose3 Tj2 = se3::fromRotationTranslation(Tj.linear() * so3::Exp(dtheta), Tj.translation() + d);
  for (const auto& [rot, shift] :
       {std::pair{dtheta, Vec3::Zero().eval()}, std::pair{Vec3::Zero().eval(), d}, std::pair{dtheta, d}}) {
    const Pose3 T = se3::fromRotationTranslation(Tj.linear() * so3::Exp(rot), Tj.translation() + shift);
    Vec6 e;
    e << rot, Ti.linear().transpose() * shift;
    const double expected = e.dot(info * e);
    EXPECT_NEAR(residualOf(f.get(), Ti, T).squaredNorm(), expected, 1e-6 * expected);
  }
  // a rigid motion of the world leaves it unchanged
  const Pose3 G = se3::fromRotationTranslation(so3::Exp(Vec3(0.3, 0.2, -1.0)), Vec3(-4.0, 7.0, 1.0));
  EXPECT_LT((residualOf(f.get(), G * Ti, G * Tj2) - residualOf(f.get(), Ti, Tj2)).norm(), 1e-9);
  // the scaled factor: a measurement 2 % long is met by s = 1 / 1.02
  Pose3 longer = T_i_j;
  longer.translation() *= 1.02;
  std::unique_ptr<ceres::CostFunction> g(makeScaledRelativePoseFactor(longer, info));
  EXPECT_LT(residualOf(g.get(), Ti, Tj, 1.0 / 1.02).norm(), 1e-12);
  EXPECT_GT(residualOf(g.get(), Ti, Tj, 1.0).norm(), 0.1);
}
