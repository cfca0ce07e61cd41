// Camera effects over time: a rolling-shutter image is made of the rows of global-shutter images
// taken at the row times (and a vertical edge seen while yawing is sheared by the analytic amount);
// the auto-exposure controller brings the image mean to its target after a bright-to-dark change
// within the stated number of frames, exposure first, then gain.
#include <gtest/gtest.h>

#include "livo/sim/auto_exposure.hpp"
#include "livo/sim/camera_renderer.hpp"
#include "sim_test_support.hpp"

using namespace livo;
using namespace livo::sim;

namespace {

CameraRig smallCamera() {
  CameraRig c;
  c.width = 96;
  c.height = 72;
  c.fx = c.fy = 60.0;
  c.cx = 47.5;
  c.cy = 35.5;
  c.rate_hz = 20;
  return c;
}

/// A wall at distance 4 m in front of a camera looking along world +x (camera z = world x, camera
/// y down); `split_y` > 0 makes its left half (world y > 0) white and its right half black,
/// otherwise it is a checkerboard of `level` and level / 4.
Scene wallScene(double level, bool split) {
  Scene scene;
  scene.lighting.ambient = 1.0;
  scene.lighting.diffuse = 0.0;
  TextureOptions t;
  t.pattern = TexturePattern::kChecker;
  t.scale = 0.3;
  t.color_a = Eigen::Vector3d::Constant(level);
  t.color_b = Eigen::Vector3d::Constant(level / 4);
  t.grain = 0.0;
  t.variation = 0.0;
  scene.addTexture(t);
  TextureOptions white = t, black = t;
  white.pattern = black.pattern = TexturePattern::kUniform;
  white.color_a = Eigen::Vector3d::Constant(0.9);
  black.color_a = Eigen::Vector3d::Constant(0.1);
  scene.addTexture(white);
  scene.addTexture(black);
  Shape half;
  half.type = ShapeType::kPlane;
  half.rotation = Eigen::AngleAxisd(-M_PI / 2, Vec3::UnitY()).toRotationMatrix();  // normal -x
  half.center = Vec3(4.0, 0.0, 0.0);
  half.half_size = Vec3(20.0, 20.0, 0.0);
  half.finalize();
  if (!split) {
    scene.addShape("wall", half, Material{});
  } else {
    half.half_size = Vec3(20.0, 10.0, 0.0);
    half.center = Vec3(4.0, 10.0, 0.0);
    Material m;
    m.texture = 1;
    scene.addShape("white", half, m);
    half.center = Vec3(4.0, -10.0, 0.0);
    m.texture = 2;
    scene.addShape("black", half, m);
  }
  scene.build();
  return scene;
}

/// Camera looking along world +x (body = camera), yawing at `yaw_rate` rad/s about world z.
test::ConstantMotion yawing(double yaw_rate) {
  Pose3 T = Pose3::Identity();
  T.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  // body rate about camera -y = world +z
  return test::ConstantMotion(T, Vec3::Zero(), Vec3(0, -yaw_rate, 0));
}

}  // namespace

TEST(RollingShutter, RowsAreTheGlobalShutterRowsAtTheRowTimes) {
  const CameraRig rig = smallCamera();
  const Scene scene = wallScene(0.8, false);
  CameraEffects rolling = test::plainEffects();
  rolling.rolling_shutter_s = 0.03;
  const CameraRenderer rs(rig, rolling), gs(rig, test::plainEffects());
  const test::ConstantMotion view = yawing(1.5);
  const double t_mid = 0.2;
  const CameraImage img = rs.render(scene, view, t_mid, 0, Random(1, 4));
  EXPECT_NEAR(rs.rowTimeOffset(rig.height - 1) - rs.rowTimeOffset(0), 0.03 * (rig.height - 1) / rig.height, 1e-15);
  EXPECT_DOUBLE_EQ(rs.rowTimeOffset(0) + rs.rowTimeOffset(rig.height - 1), 0.0);  // stamp: the centre row
  int differing_from_mid = 0;
  const CameraImage mid = gs.render(scene, view, t_mid, 0, Random(1, 4));
  for (int v = 0; v < rig.height; ++v) {
    const CameraImage row = gs.render(scene, view, t_mid + rs.rowTimeOffset(v), 0, Random(1, 4));
    for (int u = 0; u < rig.width; ++u) {
      const size_t k = static_cast<size_t>(v) * rig.width + u;
      ASSERT_EQ(img.data[k], row.data[k]) << "pixel " << u << ", " << v;
      differing_from_mid += img.data[k] != mid.data[k];
    }
  }
  EXPECT_GT(differing_from_mid, rig.width * rig.height / 10);  // the view did move
}

TEST(RollingShutter, AVerticalEdgeSeenWhileYawingIsShearedByTheAnalyticAmount) {
  const CameraRig rig = smallCamera();
  const Scene scene = wallScene(0.8, true);
  CameraEffects rolling = test::plainEffects();
  rolling.rolling_shutter_s = 0.05;
  const CameraRenderer rs(rig, rolling);
  const double yaw_rate = 1.0;  // rad/s, the edge moves right in the image while the camera turns left
  const CameraImage img = rs.render(scene, yawing(yaw_rate), 0.0, 0, Random(1, 4));
  // row v sees the edge (world y = 0 on the wall, straight ahead at t = 0) at yaw angle w * dt(v):
  // u = cx + fx * tan(w dt)
  for (int v = 0; v < rig.height; ++v) {
    const double expected_u = rig.cx + rig.fx * std::tan(yaw_rate * rs.rowTimeOffset(v));
    // the edge is between the last white pixel and the first black one
    int last_white = -1;
    for (int u = 0; u < rig.width; ++u)
      if (img.data[static_cast<size_t>(v) * rig.width + u] > 128) last_white = u;
    ASSERT_GE(last_white, 0);
    EXPECT_LE(last_white, expected_u + 1e-9) << "row " << v;
    EXPECT_GT(last_white + 1, expected_u - 1e-9) << "row " << v;
  }
  // the shear across the image: (tan(w r/2) - tan(-w r/2)) fx ~ 3 px
  EXPECT_GT(rig.fx * 2 * std::tan(yaw_rate * rs.rowTimeOffset(rig.height - 1)), 2.5);
}

TEST(AutoExposure, ConvergesToTheTargetAfterABrightToDarkChangeWithinSevenFrames) {
  const CameraRig rig = smallCamera();
  const Scene bright = wallScene(0.8, false), dark = wallScene(0.08, false);
  CameraEffects e = test::plainEffects();
  e.exposure_time = 0.005;
  e.auto_exposure.enabled = true;
  e.auto_exposure.target_mean = 100.0;
  e.auto_exposure.max_exposure = 0.02;
  e.auto_exposure.rate = 0.5;
  const CameraRenderer renderer(rig, e);
  AutoExposure controller(e.auto_exposure, e.exposure_time);
  const test::ConstantMotion still = yawing(0.0);
  auto frame = [&](const Scene& scene, int k) {
    const ExposureSetting used = controller.setting();
    const CameraImage img = renderer.render(scene, still, 0.05 * k, 0, Random(1, 4, k), used);
    EXPECT_FLOAT_EQ(img.exposure_time, static_cast<float>(used.exposure));
    const double mean = AutoExposure::meanLevel(img.data);
    controller.update(mean);
    return mean;
  };
  int k = 0;
  for (; k < 12; ++k) frame(bright, k);
  EXPECT_NEAR(frame(bright, k++), 100.0, 2.0);
  const double bright_exposure = controller.setting().exposure;
  EXPECT_LT(bright_exposure, 0.02);
  EXPECT_DOUBLE_EQ(controller.setting().gain, 1.0);  // exposure alone suffices
  // 10 x darker: the first dark frame is about a tenth of the target, then within 2 % by frame 7
  std::vector<double> means;
  for (int i = 0; i < 8; ++i) means.push_back(frame(dark, k++));
  EXPECT_NEAR(means[0], 10.0, 1.5);
  for (int i = 1; i < 8; ++i) EXPECT_GT(means[i], means[i - 1] - 1.0);  // no overshoot-undershoot ringing
  EXPECT_NEAR(means[7], 100.0, 2.0);
  // needing 10 x the bright exposure, past the exposure limit: the gain makes up the rest
  EXPECT_DOUBLE_EQ(controller.setting().exposure, 0.02);
  EXPECT_NEAR(controller.setting().gain, 10.0 * bright_exposure / 0.02, 0.03 * 10.0 * bright_exposure / 0.02);
}

TEST(AutoExposure, ControllerStepsFollowTheLogDomainLaw) {
  AutoExposureOptions o;
  o.enabled = true;
  o.target_mean = 100.0;
  o.min_exposure = 1e-4;
  o.max_exposure = 0.01;
  o.max_gain = 8.0;
  o.rate = 0.5;
  AutoExposure c(o, 0.004);
  c.update(25.0);  // 4 x too dark: total x 2
  EXPECT_NEAR(c.setting().exposure, 0.008, 1e-12);
  EXPECT_DOUBLE_EQ(c.setting().gain, 1.0);
  c.update(25.0);  // x 2 again: exposure capped at 10 ms, gain 1.6
  EXPECT_DOUBLE_EQ(c.setting().exposure, 0.01);
  EXPECT_NEAR(c.setting().gain, 1.6, 1e-12);
  for (int i = 0; i < 20; ++i) c.update(1.0);  // black: gain saturates
  EXPECT_DOUBLE_EQ(c.setting().gain, 8.0);
  for (int i = 0; i < 40; ++i) c.update(255.0);  // saturated white: gain first back to 1, exposure down
  EXPECT_DOUBLE_EQ(c.setting().gain, 1.0);
  EXPECT_DOUBLE_EQ(c.setting().exposure, 1e-4);
}

TEST(Vignetting, CornersLoseTheConfiguredShareQuadraticallyWithRadius) {
  const CameraRig rig = smallCamera();
  Scene scene;  // a uniform wall filling the view, lit evenly
  scene.lighting.ambient = 1.0;
  scene.lighting.diffuse = 0.0;
  TextureOptions t;
  t.pattern = TexturePattern::kUniform;
  t.color_a = Eigen::Vector3d::Constant(0.8);
  t.grain = 0.0;
  t.variation = 0.0;
  scene.addTexture(t);
  Shape wall;
  wall.type = ShapeType::kPlane;
  wall.rotation = Eigen::AngleAxisd(-M_PI / 2, Vec3::UnitY()).toRotationMatrix();
  wall.center = Vec3(4.0, 0.0, 0.0);
  wall.half_size = Vec3(50.0, 50.0, 0.0);
  scene.addShape("wall", wall, Material{});
  scene.build();
  CameraEffects e = test::plainEffects();
  e.vignetting = 0.3;
  const CameraImage img = CameraRenderer(rig, e).render(scene, yawing(0.0), 0.0, 0, Random(1, 4));
  const double half_diag2 = 0.25 * (rig.width * rig.width + rig.height * rig.height);
  for (int v = 0; v < rig.height; v += 7)
    for (int u = 0; u < rig.width; u += 5) {
      const double r2 = (u - rig.cx) * (u - rig.cx) + (v - rig.cy) * (v - rig.cy);
      EXPECT_NEAR(img.data[static_cast<size_t>(v) * rig.width + u],
                  204.0 * (1.0 - 0.3 * std::min(1.0, r2 / half_diag2)), 0.5 + 1e-6)
          << u << ", " << v;
    }
  // the corner pixel (0, 0) lies just inside the half diagonal: about 30 % darker than the centre
  EXPECT_NEAR(img.data[0] / 204.0, 0.7, 0.01);
}
