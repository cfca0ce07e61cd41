// The visual subsystem's motion as livo-lio-graph takes it (visual_motion.hpp): relative poses
// interpolated between samples, independent of the visual world's frame, refused out of span,
// across epochs, out of order or non-finite.
#include <gtest/gtest.h>

#include <cmath>

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
  for (int k = 0; k <= 40; ++k)
    ASSERT_TRUE(vm.add(VisualSample{1'000'000 + k * 50'000, bodyAt(0.05 * k, G), 0}));
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
