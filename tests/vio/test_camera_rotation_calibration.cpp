// The camera rotation calibration from image pairs (camera_rotation_calibration.hpp): the solver
// against constructed pairs with a known rotation, and the whole path (KLT, RANSAC, solver) on
// images the simulator renders through a camera mounted with a known error.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "../temp_path.hpp"
#include "livo/camera_projection.hpp"
#include "livo/config.hpp"
#include "livo/so3.hpp"
#include "livo/vio/camera_rotation_calibration.hpp"
#include "sim_fixture.hpp"

namespace {

using livo::Mat3;
using livo::Pose3;
using livo::Vec3;
using livo::vio::RotationEstimate;
using livo::vio::TrackPair;

constexpr double kDeg = M_PI / 180.0;

Pose3 rigExtrinsic() {  // z forward camera on an x forward body, as the sim rigs mount it
  Pose3 T = Pose3::Identity();
  T.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  T.translation() = Vec3(0.08, 0.0, 0.02);
  return T;
}

Pose3 bodyOnCircle(double s) {  // planar: the body turns about its z axis only
  Pose3 T = Pose3::Identity();
  T.linear() = Eigen::AngleAxisd(s + M_PI / 2, Vec3::UnitZ()).toRotationMatrix();
  T.translation() = Vec3(3.0 * std::cos(s), 3.0 * std::sin(s), 1.5);
  return T;
}

}  // namespace

TEST(CameraProjection, PixelRayInvertsProject) {
  livo::CameraRig rig;
  rig.fx = rig.fy = 400.0;
  rig.cx = 319.5;
  rig.cy = 239.5;
  rig.distortion = {-0.05, 0.01, 0.0005, -0.0003};
  const livo::CameraProjection camera(rig);
  for (const Eigen::Vector2d& px : {Eigen::Vector2d(3, 4), Eigen::Vector2d(320, 240), Eigen::Vector2d(630, 470)}) {
    Eigen::Vector2d back;
    ASSERT_TRUE(camera.project(camera.pixelRay(px) * 3.0, &back));
    EXPECT_LT((back - px).norm(), 1e-9) << px.transpose();
  }
}

TEST(CameraRotationSolver, FindsTheRotationOfAPlanarRigFromNoisyPairsWithOutliers) {
  // a yaw-only circle in a room: the rotation about the yaw axis and both others must come out
  const Pose3 T_rig = rigExtrinsic();
  const Vec3 phi_true = Vec3(0.4, -0.3, 0.25) * kDeg;
  Pose3 T_true = T_rig;
  T_true.linear() = T_rig.linear() * livo::so3::Exp(phi_true);
  const double focal = 400.0;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> wall(-6.0, 6.0), height(0.0, 3.0), unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.3 / focal);
  std::vector<Vec3> points;  // on the walls of a 12 m room
  for (int i = 0; i < 4000; ++i) {
    const double a = wall(rng), z = height(rng);
    const int side = i % 4;
    points.push_back(side == 0 ? Vec3(6, a, z) : side == 1 ? Vec3(-6, a, z) : side == 2 ? Vec3(a, 6, z) : Vec3(a, -6, z));
  }
  std::deque<TrackPair> pairs;
  for (int k = 0; k < 120; ++k) {
    TrackPair p;
    p.T_W_I0 = bodyOnCircle(0.05 * k);
    p.T_W_I1 = bodyOnCircle(0.05 * k + 0.08);
    const Pose3 C0 = (p.T_W_I0 * T_true).inverse(), C1 = (p.T_W_I1 * T_true).inverse();
    for (const Vec3& X : points) {
      const Vec3 a = C0 * X, b = C1 * X;
      if (a.z() < 0.5 || b.z() < 0.5 || std::abs(a.x() / a.z()) > 0.8 || std::abs(b.x() / b.z()) > 0.8 ||
          std::abs(a.y() / a.z()) > 0.6 || std::abs(b.y() / b.z()) > 0.6 || unit(rng) > 0.3)
        continue;
      Vec3 x0(a.x() / a.z() + noise(rng), a.y() / a.z() + noise(rng), 1.0);
      Vec3 x1(b.x() / b.z() + noise(rng), b.y() / b.z() + noise(rng), 1.0);
      if (unit(rng) < 0.1) x1.head<2>() += Eigen::Vector2d(unit(rng) - 0.5, unit(rng) - 0.5) * (40.0 / focal);
      p.x0.push_back(x0);
      p.x1.push_back(x1);
    }
    ASSERT_GT(p.x0.size(), 20u);
    pairs.push_back(std::move(p));
  }
  const RotationEstimate e = livo::vio::solveCameraRotation(pairs, T_rig, Vec3::Zero(), 1.0 / focal, focal);
  const Vec3 err = e.correction - phi_true;
  // unbiased, and as well known as it says (the pairs' noise is independent here)
  for (int a = 0; a < 3; ++a) {
    EXPECT_LT(std::abs(err[a]) / kDeg, 0.04) << "axis " << a << ": " << (e.correction / kDeg).transpose();
    EXPECT_LT(std::abs(err[a]), 3.0 * std::sqrt(e.covariance(a, a))) << "axis " << a << " outside 3 sigma";
  }
  EXPECT_LT(e.maxStdDeg(), 0.03);
  EXPECT_LT(e.rms_px, 0.6);
  EXPECT_EQ(e.pairs, 120);
}

namespace {

/// The calibration on 18 s of images (10 Hz) the simulator rendered from `config` through a
/// camera turned by `rpy_err` (rad), with the true body poses (a perfect LIO) and the body rate.
RotationEstimate calibrateOnRenderedImages(const std::string& config, const Vec3& rpy_err, bool* converged,
                                           int* pairs) {
  livo_test::SimScene scene(config);
  Pose3 T_err = Pose3::Identity();
  T_err.linear() = livo::so3::Exp(rpy_err);
  scene.mountCameraWithError(T_err);
  livo::vio::RotationCalibrationOptions o;
  o.enabled = true;
  o.min_pairs = 20;
  o.apply_std_deg = 0.05;
  const livo::CameraProjection camera(scene.camera());
  livo::vio::CameraRotationCalibration cal(o, camera, scene.camera().T_I_C);
  livo::vio::RollingShutter shutter =
      livo::vio::RollingShutter::fromReadout(scene.camera().rolling_shutter_s, scene.camera().height);
  for (int k = 0; k < 180; ++k) {
    const double t = 4.0 + 0.1 * k;
    const auto truth = scene.setup().trajectory->at(t);
    shutter.omega_I = truth.angular_velocity;
    cal.addImage(scene.image(t, static_cast<uint64_t>(k)).pixels, scene.utime(t), truth.T_W_I, truth.velocity, shutter);
  }
  *converged = cal.converged();
  *pairs = cal.pairsClosed();
  return cal.estimate();
}

void expectRotation(const RotationEstimate& e, const Vec3& truth, double tolerance_deg) {
  const Vec3 err = e.correction - truth;
  for (int a = 0; a < 3; ++a)
    EXPECT_LT(std::abs(err[a]) / kDeg, tolerance_deg) << "axis " << a << ": " << (e.correction / kDeg).transpose();
}

}  // namespace

TEST(CameraRotationCalibration, FindsTheMountingErrorOfARenderedCamera) {
  // the calibration believes the rig's extrinsic, so it must find the mounting error's rotation
  const Vec3 rpy_err = Vec3(0.35, -0.25, 0.3) * kDeg;
  bool converged = false;
  int pairs = 0;
  const RotationEstimate e = calibrateOnRenderedImages("config/sim/room.yaml", rpy_err, &converged, &pairs);
  ASSERT_GE(pairs, 100);
  EXPECT_TRUE(converged) << "1-sigma " << e.maxStdDeg() << " deg";
  expectRotation(e, rpy_err, 0.05);
  for (int a = 0; a < 3; ++a)  // and as well known as it says
    EXPECT_LT(std::abs(e.correction[a] - rpy_err[a]), 3.0 * std::sqrt(e.covariance(a, a))) << "axis " << a;
  EXPECT_LT(e.rms_px, 0.5);
}

TEST(CameraRotationCalibration, FindsTheMountingErrorThroughARollingShutter) {
  // room_hard: a 20 ms rolling shutter, auto exposure, motion blur, people and cars moving through
  // the view. Measured: (-0.289, 0.251, 0.248) deg for (-0.3, 0.2, 0.25); without the rows' rotation
  // (-0.271, 0.332, 0.360), without their readout baseline (-0.259, 0.259, 0.245). The 0.05 deg
  // left about the camera's y axis (the body's yaw; the trajectory turns mostly one way) is beyond
  // the estimate's 1-sigma and not explained yet.
  const Vec3 rpy_err = Vec3(-0.3, 0.2, 0.25) * kDeg;
  bool converged = false;
  int pairs = 0;
  const RotationEstimate e = calibrateOnRenderedImages("config/sim/room_hard.yaml", rpy_err, &converged, &pairs);
  ASSERT_GE(pairs, 100);
  EXPECT_TRUE(converged) << "1-sigma " << e.maxStdDeg() << " deg";
  expectRotation(e, rpy_err, 0.06);
}

TEST(CameraRotationOverlay, FusesThePairsWithTheRigAndMergesOverTheConfig) {
  const Pose3 rig = rigExtrinsic();
  RotationEstimate e;
  e.correction = Vec3(-0.12, -0.08, 0.24) * kDeg;
  e.covariance = Vec3(0.03, 0.06, 0.3).cwiseAbs2().asDiagonal();
  e.covariance *= kDeg * kDeg;
  e.pairs = 300;
  const double rig_std = 0.3 * kDeg;

  // per axis (diagonal covariances): the precision-weighted mean of the pairs and the rig (0)
  const livo::vio::FusedCameraRotation f = livo::vio::fuseWithRig(rig, e, rig_std);
  for (int k = 0; k < 3; ++k) {
    const double v = e.covariance(k, k), v0 = rig_std * rig_std;
    EXPECT_NEAR(f.correction(k), e.correction(k) * v0 / (v0 + v), 1e-12);
    EXPECT_NEAR(f.covariance(k, k), v * v0 / (v + v0), 1e-18);
  }
  EXPECT_NEAR(f.correction.x() / e.correction.x(), 0.99, 0.005);  // a sure axis: nearly whole
  EXPECT_NEAR(f.correction.z() / e.correction.z(), 0.5, 1e-9);    // as vague as the rig: half
  EXPECT_TRUE(f.T_I_C.translation().isApprox(rig.translation()));
  EXPECT_LT(livo::so3::Log(f.T_I_C.linear().transpose() * rig.linear() * livo::so3::Exp(f.correction)).norm(), 1e-12);
  // no stated rig uncertainty: the pairs' estimate whole
  EXPECT_TRUE(livo::vio::fuseWithRig(rig, e, 0.0).correction.isApprox(e.correction, 1e-12));

  // the overlay replaces the rig's T_I_C whatever form it had, and nothing else
  const std::string config = livo_test::tempPath("rig.yaml"), overlay = livo_test::tempPath("camera_rotation.yaml");
  std::ofstream(config) << "rig:\n  camera: {width: 640, T_I_C: {translation: [0.08, 0, 0.02], rpy_deg: [-90, 0, -90]}}\n"
                           "vio: {update: {noise_std: 30}}\n";
  std::ofstream(overlay) << livo::vio::cameraRotationOverlay(f, e, 432, rig_std);
  const livo::Config merged = livo::Config::load(config, {overlay});
  const livo::Config camera = merged.section("rig").section("camera");
  const Pose3 T = camera.get<Eigen::Isometry3d>("T_I_C");
  EXPECT_LT((T.matrix() - f.T_I_C.matrix()).cwiseAbs().maxCoeff(), 1e-8);  // 9 decimals
  EXPECT_EQ(camera.get<int>("width"), 640);
  EXPECT_EQ(merged.section("vio").section("update").get<int>("noise_std"), 30);
  EXPECT_EQ(camera.keys(), (std::vector<std::string>{"width", "T_I_C"}));
}
