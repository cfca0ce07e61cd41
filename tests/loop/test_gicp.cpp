#include <gtest/gtest.h>

#include <random>

#include "livo/loop/gicp.hpp"
#include "livo/loop/loop_registration.hpp"
#include "livo/loop/voxel_grid.hpp"
#include "synthetic_scenes.hpp"

namespace livo::loop {
namespace {
using namespace livo::loop::testing;

// The fine stage converges from a coarse-stage-sized error (2 degrees, 0.4 m) on partially
// overlapping noisy views.
TEST(Gicp, ConvergesFromCoarseResult) {
  const Points scene = makeScene(31);
  const Pose3 W_T_t = yawPose(0.1, Vec3(0, 0, 1.8));
  const Pose3 W_T_s = yawPose(0.9, Vec3(4.0, 1.5, 1.8));
  const GicpCloud target =
      GicpCloud::build(centroidPerVoxel(viewFrom(scene, W_T_t.translation(), 0.1, 25, 0.01, 1), 0.3));
  const GicpCloud source =
      GicpCloud::build(centroidPerVoxel(viewFrom(scene, W_T_s.translation(), 0.9, 25, 0.01, 2), 0.3));
  const Pose3 truth = W_T_t.inverse() * W_T_s;
  for (const Vec3& dr : {Vec3(0, 0, 0.035), Vec3(0.01, -0.01, -0.035)}) {
    Pose3 init = truth;
    init.linear() = so3::Exp(dr) * init.linear();
    init.translation() += Vec3(0.3, -0.25, 0.1);
    GicpOptions o;
    const GicpResult r = gicpRegister(source, target, init, o);
    EXPECT_TRUE(r.converged);
    EXPECT_LT(rotationErrorDeg(r.T_target_source, truth), 0.1);
    EXPECT_LT(translationError(r.T_target_source, truth), 0.03);
    EXPECT_GT(r.overlap, 0.5);
    EXPECT_LT(r.fitness, 0.02);
  }
}

// A straight corridor (floor, ceiling, two walls, 3 x 3 m) seen from x = 0 and x = 5: GICP fits
// it perfectly at any offset along the axis, as the two false loops on config/sim/corridor.yaml
// did (fitness 0.05-0.07, overlap 0.87-0.91, absolute translation eigenvalue 0.8-1.8, above its
// 0.05 bound). The eigenvalue ratio tells it from a well-conditioned scene.
TEST(Gicp, CorridorIsDegenerateByEigenvalueRatio) {
  const GicpCloud target = GicpCloud::build(centroidPerVoxel(corridorView(0.0, 1), 0.4));
  const GicpCloud source = GicpCloud::build(centroidPerVoxel(corridorView(5.0, 2), 0.4));
  const GicpResult r = gicpRegister(source, target, Pose3::Identity(), {});  // truth: 5 m along x
  EXPECT_TRUE(r.converged);
  EXPECT_GT(r.overlap, 0.5);  // a perfect-looking fit ...
  EXPECT_LT(r.fitness, 0.15);
  EXPECT_GT(r.min_translation_eigenvalue, AcceptanceOptions{}.min_translation_eigenvalue);  // ... the old check passes
  EXPECT_LT(r.translation_eigenvalue_ratio, AcceptanceOptions{}.min_translation_eigenvalue_ratio);

  const Points scene = makeScene(31);
  const GicpCloud t2 = GicpCloud::build(centroidPerVoxel(viewFrom(scene, Vec3(0, 0, 1.8), 0.1, 25, 0.01, 1), 0.4));
  const GicpCloud s2 = GicpCloud::build(centroidPerVoxel(viewFrom(scene, Vec3(4.0, 1.5, 1.8), 0.9, 25, 0.01, 2), 0.4));
  const Pose3 truth = yawPose(0.1, Vec3(0, 0, 1.8)).inverse() * yawPose(0.9, Vec3(4.0, 1.5, 1.8));
  const GicpResult ok = gicpRegister(s2, t2, truth, {});
  EXPECT_GT(ok.translation_eigenvalue_ratio, 5 * AcceptanceOptions{}.min_translation_eigenvalue_ratio);
}

TEST(Gicp, EmptyCloudsDoNotConverge) {
  const GicpCloud empty = GicpCloud::build({});
  const GicpCloud some = GicpCloud::build(centroidPerVoxel(makeScene(3), 1.0));
  EXPECT_FALSE(gicpRegister(empty, some, Pose3::Identity(), {}).converged);
  EXPECT_FALSE(gicpRegister(some, empty, Pose3::Identity(), {}).converged);
}

}  // namespace
}  // namespace livo::loop
