// Camera: a rendered checkerboard plane landing on the pixels the model predicts, a fisheye
// (equidistant) rig's render against the model's projection, exposure changes and motion blur.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "livo/camera_projection.hpp"
#include "livo/sim/camera_renderer.hpp"
#include "livo/sim/random.hpp"
#include "sim_test_support.hpp"

using namespace livo;
using namespace livo::sim;

namespace {

CameraRig testCamera() {
  CameraRig c;
  c.width = 320;
  c.height = 240;
  c.fx = 210.0;
  c.fy = 205.0;
  c.cx = 161.3;
  c.cy = 118.7;
  c.distortion = {-0.28, 0.07, 0.0002, 1.8e-5};  // EuRoC cam0-like
  c.rate_hz = 20;
  c.T_I_C.linear() = so3::Exp(Vec3(0.02, 0.01, -0.03));
  c.T_I_C.translation() = Vec3(0.05, 0.0, 0.0);
  return c;
}

// Checkerboard plane z = 4 (normal towards the camera), squares of 0.25 m, lit uniformly.
constexpr double kPlaneZ = 4.0, kSquare = 0.25;
const Vec3 kPlaneCenter(0.2, -0.1, kPlaneZ);

Scene checkerScene() {
  Scene scene;
  scene.lighting.ambient = 1.0;
  scene.lighting.diffuse = 0.0;
  TextureOptions t;
  t.pattern = TexturePattern::kChecker;
  t.scale = kSquare;
  t.color_a = Eigen::Vector3d::Constant(0.9);
  t.color_b = Eigen::Vector3d::Constant(0.1);
  t.grain = 0.0;
  t.variation = 0.0;
  scene.addTexture(t);
  Shape plane;
  plane.type = ShapeType::kPlane;
  plane.center = kPlaneCenter;
  plane.half_size = Vec3(3.0, 3.0, 0.0);
  scene.addShape("board", plane, Material{});
  scene.build();
  return scene;
}

Pose3 bodyPose() {
  Pose3 T = Pose3::Identity();
  T.linear() = so3::Exp(Vec3(0.05, -0.04, 0.1));
  T.translation() = Vec3(0.1, 0.2, 0.0);
  return T;
}

}  // namespace

// The renderer casts its rays through common's CameraProjection (the camera model lives there
// once; tests/unit/test_camera_projection.cpp checks it against OpenCV for both distortion models).
// A fisheye rig (equidistant, TUM-VI's cam0): bright balls at known points, over 60 degrees off
// axis, appear centred where CameraProjection::project puts them.
TEST(CameraRenderer, EquidistantRigPutsKnownPointsWhereTheModelProjectsThem) {
  CameraRig rig;
  rig.width = rig.height = 512;
  rig.fx = 190.97847715128717;
  rig.fy = 190.9733070521226;
  rig.cx = 254.93170605935475;
  rig.cy = 256.8974428996504;
  rig.distortion_model = DistortionModel::kEquidistant;
  rig.distortion = {0.0034823894022493434, 0.0007150348452162257, -0.0020532361418706202, 0.00020293673591811182};
  Scene scene;
  scene.lighting.ambient = 1.0;
  scene.lighting.diffuse = 0.0;
  scene.sky.horizon = scene.sky.zenith = Eigen::Vector3d::Zero();
  TextureOptions white;
  white.pattern = TexturePattern::kUniform;
  white.color_a = Eigen::Vector3d::Constant(0.9);
  white.grain = white.variation = 0.0;
  scene.addTexture(white);
  std::vector<Vec3> centres;
  for (const double off_axis_deg : {0.0, 25.0, 45.0, 62.0})
    for (int k = 0; k < (off_axis_deg == 0.0 ? 1 : 6); ++k) {
      const double a = off_axis_deg * M_PI / 180.0, b = k * M_PI / 3.0 + 0.2;
      centres.push_back(3.0 * Vec3(std::sin(a) * std::cos(b), std::sin(a) * std::sin(b), std::cos(a)));
      Shape ball;
      ball.type = ShapeType::kSphere;
      ball.center = centres.back();
      ball.half_size = Vec3::Constant(0.12);
      scene.addShape("ball" + std::to_string(centres.size()), ball, Material{});
    }
  scene.build();
  CameraRenderer renderer(rig, test::plainEffects());
  test::ConstantMotion still(Pose3::Identity());  // T_W_C = identity: camera frame = world frame
  const CameraImage img = renderer.render(scene, still, 0.0, 1, Random(1, 4));
  const CameraProjection model(rig);
  double worst = 0.0;
  for (const Vec3& c : centres) {
    Eigen::Vector2d predicted;
    ASSERT_TRUE(model.project(c, &predicted)) << c.transpose();
    // the ball's brightness centroid in a window round the prediction
    double sum = 0.0, su = 0.0, sv = 0.0;
    const int u0 = static_cast<int>(std::lround(predicted.x())), v0 = static_cast<int>(std::lround(predicted.y()));
    for (int v = v0 - 15; v <= v0 + 15; ++v)
      for (int u = u0 - 15; u <= u0 + 15; ++u) {
        if (u < 0 || v < 0 || u >= rig.width || v >= rig.height) continue;
        const double g = img.data[static_cast<size_t>(v) * rig.width + u];
        sum += g, su += g * u, sv += g * v;
      }
    ASSERT_GT(sum, 255.0 * 20) << "the ball at " << c.transpose() << " is seen";
    const double error = (Eigen::Vector2d(su / sum, sv / sum) - predicted).norm();
    EXPECT_LT(error, 0.35) << "ball at " << c.transpose() << ", predicted " << predicted.transpose();
    worst = std::max(worst, error);
  }
  std::printf("equidistant render: %zu balls, worst centroid offset %.3f px\n", centres.size(), worst);
}

TEST(CameraRenderer, CheckerboardLandsOnThePredictedPixels) {
  const CameraRig rig = testCamera();
  const Scene scene = checkerScene();
  CameraRenderer renderer(rig, test::plainEffects());
  test::ConstantMotion still(bodyPose());
  const CameraImage img = renderer.render(scene, still, 0.0, 42, Random(1, 4));
  ASSERT_EQ(img.width, 320);
  ASSERT_EQ(img.data.size(), 320u * 240u);
  EXPECT_EQ(img.utime, 42);
  const Pose3 T_W_C = bodyPose() * rig.T_I_C;
  int checked = 0, white = 0;
  for (int v = 0; v < rig.height; ++v)
    for (int u = 0; u < rig.width; ++u) {
      // where this pixel looks on the plane, from the camera model alone
      const Vec3 d = T_W_C.linear() * renderer.camera().pixelRay(Eigen::Vector2d(u, v));
      const double t = (kPlaneZ - T_W_C.translation().z()) / d.z();
      const Vec3 p = T_W_C.translation() + t * d - kPlaneCenter;
      if (std::abs(p.x()) > 2.9 || std::abs(p.y()) > 2.9) continue;
      const double fu = p.x() / kSquare - std::floor(p.x() / kSquare),
                   fv = p.y() / kSquare - std::floor(p.y() / kSquare);
      const double margin = 0.03 / kSquare;  // stay 3 cm (a few pixels) off the square edges
      if (fu < margin || fu > 1 - margin || fv < margin || fv > 1 - margin) continue;
      const int64_t a = static_cast<int64_t>(std::floor(p.x() / kSquare)),
                    b = static_cast<int64_t>(std::floor(p.y() / kSquare));
      const bool is_white = ((a + b) % 2 + 2) % 2 == 0;
      const int expected = is_white ? 230 : 26;  // 255 * 0.9, 255 * 0.1
      ASSERT_NEAR(img.data[static_cast<size_t>(v) * rig.width + u], expected, 1) << "pixel " << u << ", " << v;
      ++checked;
      white += is_white;
    }
  EXPECT_GT(checked, 320 * 240 * 2 / 5);  // most of the image sees the board
  EXPECT_GT(white, checked / 3);
  EXPECT_LT(white, 2 * checked / 3);
}

TEST(CameraRenderer, ExposureChangesScaleTheImage) {
  CameraRig rig = testCamera();
  rig.color = true;
  const Scene scene = checkerScene();
  CameraEffects e = test::plainEffects();
  e.exposure_variation = 0.3;
  e.brightness = 0.8;
  CameraRenderer renderer(rig, e);
  test::ConstantMotion still(bodyPose());
  // two times with clearly different exposures
  double ta = 0.0, tb = 0.0;
  for (double t = 0.0; t < 8.0; t += 0.05) {
    if (renderer.exposureAt(t) > renderer.exposureAt(ta)) ta = t;
    if (renderer.exposureAt(t) < renderer.exposureAt(tb)) tb = t;
  }
  const CameraImage a = renderer.render(scene, still, ta, 0, Random(1, 4, 0));
  const CameraImage b = renderer.render(scene, still, tb, 0, Random(1, 4, 1));
  ASSERT_EQ(a.data.size(), 320u * 240u * 3u);
  EXPECT_FLOAT_EQ(a.exposure_time, static_cast<float>(renderer.exposureAt(ta)));
  double sa = 0, sb = 0;
  for (size_t i = 0; i < a.data.size(); ++i) sa += a.data[i], sb += b.data[i];
  const double ratio = renderer.exposureAt(ta) / renderer.exposureAt(tb);
  EXPECT_GT(ratio, 1.3);
  EXPECT_NEAR(sa / sb, ratio, 0.01 * ratio);
}

TEST(CameraRenderer, MotionBlurSmoothsAMovingView) {
  const CameraRig rig = testCamera();
  const Scene scene = checkerScene();
  CameraEffects sharp = test::plainEffects(), blurred = test::plainEffects();
  sharp.exposure_time = blurred.exposure_time = 0.02;
  blurred.motion_blur_samples = 8;
  test::ConstantMotion pan(bodyPose(), Vec3(2.0, 0, 0), Vec3(0, 1.5, 0));
  const CameraImage a = CameraRenderer(rig, sharp).render(scene, pan, 0.5, 0, Random(1, 4));
  const CameraImage b = CameraRenderer(rig, blurred).render(scene, pan, 0.5, 0, Random(1, 4));
  auto gradient = [&](const CameraImage& im) {  // energy of horizontal gradients
    double g = 0;
    for (int v = 0; v < im.height; ++v)
      for (int u = 1; u < im.width; ++u) {
        const double d = im.data[v * im.width + u] - im.data[v * im.width + u - 1];
        g += d * d;
      }
    return g;
  };
  EXPECT_LT(gradient(b), 0.7 * gradient(a));
}
