// Jacobians against numeric differentiation: the distorted projection (common
// CameraProjection), the pixel wrt the body pose error (right perturbation of W_R_I, W_p_I), and
// the photometric residual of a patch wrt the pose error with the brightness fit projected out.
#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/core.hpp>

#include "livo/camera_projection.hpp"
#include "livo/vio/photometric_residual.hpp"

using namespace livo;
using namespace livo::vio;

namespace {

CameraRig distortedCamera() {
  CameraRig c;
  c.width = 640;
  c.height = 512;
  c.fx = 410.0;
  c.fy = 405.0;
  c.cx = 322.3;
  c.cy = 251.8;
  c.distortion = {{-0.28, 0.09, 0.0012, -0.0008}};  // strong barrel, as on a wide lens
  c.T_I_C = se3::fromRotationTranslation(so3::Exp(Vec3(-M_PI / 2, 0.0, -M_PI / 2)) * so3::Exp(Vec3(0.01, -0.02, 0.015)),
                                         Vec3(0.08, -0.01, 0.02));
  return c;
}

FilterState bodyState() {
  FilterState x;
  x.rot = so3::Exp(Vec3(0.05, -0.1, 0.7));
  x.pos = Vec3(1.0, -2.0, 1.4);
  return x;
}

// A world point seen by the body state's camera at normalised image coordinates (u, v), depth z.
Vec3 worldPoint(const CameraRig& cam, const FilterState& x, double u, double v, double z) {
  return x.pose() * (cam.T_I_C * Vec3(u * z, v * z, z));
}

// An image whose pyramid level `level` is exactly the bilinear function
//   g(i, j) = 128 + 3 di + 2 dj + di dj,  di = clamp(i - i0, -9, 9), dj likewise
// (level-0 pixels repeated in 2^level blocks, so the 2x2 averages reproduce g). On it the
// bilinear interpolation is exact and so are central differences: the analytic Jacobian must
// match the numeric one to rounding.
cv::Mat saddleImage(int w, int h, int level, int i0, int j0) {
  cv::Mat img(h, w, CV_8UC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int di = std::clamp((x >> level) - i0, -9, 9), dj = std::clamp((y >> level) - j0, -9, 9);
      img.at<uint8_t>(y, x) = static_cast<uint8_t>(128 + 3 * di + 2 * dj + di * dj);
    }
  return img;
}

}  // namespace

TEST(VioJacobians, DistortionJacobianMatchesNumeric) {
  const CameraProjection cam(distortedCamera());
  for (const Eigen::Vector2d& xy : {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.41, -0.33), Eigen::Vector2d(-0.62, 0.47)}) {
    const Eigen::Matrix2d J = cam.distortJacobian(xy);
    const double h = 1e-6;
    for (int k = 0; k < 2; ++k) {
      Eigen::Vector2d d = Eigen::Vector2d::Zero();
      d[k] = h;
      const Eigen::Vector2d num = (cam.distort(xy + d) - cam.distort(xy - d)) / (2 * h);
      EXPECT_LT((J.col(k) - num).norm(), 1e-8 * (1.0 + num.norm())) << "column " << k << " at " << xy.transpose();
    }
  }
}

TEST(VioJacobians, ProjectionJacobianWithDistortionMatchesNumeric) {
  const CameraProjection cam(distortedCamera());
  for (const Vec3& p : {Vec3(0.3, -0.2, 2.0), Vec3(-1.9, 1.4, 3.1), Vec3(2.2, 1.5, 4.0), Vec3(0.01, 0.02, 0.7)}) {
    Eigen::Vector2d px, px2;
    Eigen::Matrix<double, 2, 3> J;
    ASSERT_TRUE(cam.projectWithJacobian(p, &px, &J)) << p.transpose();
    ASSERT_TRUE(cam.project(p, &px2));
    EXPECT_EQ(px, px2);  // the same pixel as project()
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      Vec3 d = Vec3::Zero();
      d[k] = h;
      Eigen::Vector2d a, b;
      ASSERT_TRUE(cam.project(p + d, &a));
      ASSERT_TRUE(cam.project(p - d, &b));
      const Eigen::Vector2d num = (a - b) / (2 * h);
      EXPECT_LT((J.col(k) - num).norm(), 1e-5 * (1.0 + num.norm())) << "column " << k << " at " << p.transpose();
    }
  }
}

TEST(VioJacobians, PixelJacobianWrtPoseErrorMatchesNumeric) {
  const CameraRig rig = distortedCamera();
  const CameraProjection cam(rig);
  const FilterState x = bodyState();
  const Pose3 T_C_I = rig.T_I_C.inverse();
  for (const Eigen::Vector3d& uvz : {Vec3(0.1, -0.05, 2.5), Vec3(-0.55, 0.4, 4.0), Vec3(0.6, 0.45, 1.2)}) {
    const Vec3 p_W = worldPoint(rig, x, uvz.x(), uvz.y(), uvz.z());
    const Vec3 p_I = x.rot.transpose() * (p_W - x.pos);
    Eigen::Vector2d px;
    Eigen::Matrix<double, 2, 3> Jp;
    ASSERT_TRUE(cam.projectWithJacobian(T_C_I * p_I, &px, &Jp));
    const Mat26 B = pixelPoseJacobian(Jp, x.rot, rig.T_I_C, p_I);
    const double h = 1e-7;
    for (int k = 0; k < 6; ++k) {
      Vec18 d = Vec18::Zero();
      d[k] = h;
      auto pixelAt = [&](const FilterState& s) {
        Eigen::Vector2d q;
        EXPECT_TRUE(cam.project(T_C_I * (s.rot.transpose() * (p_W - s.pos)), &q));
        return q;
      };
      const Eigen::Vector2d num = (pixelAt(x.boxplus(d)) - pixelAt(x.boxplus(-d))) / (2 * h);
      EXPECT_LT((B.col(k) - num).norm(), 1e-5 * (1.0 + num.norm())) << "column " << k;
      EXPECT_GT(B.col(k).norm(), 1.0);  // every pose direction moves the pixel
    }
  }
}

TEST(VioJacobians, PhotometricJacobianWrtPoseErrorMatchesNumeric) {
  const CameraRig rig = distortedCamera();
  const CameraProjection cam(rig);
  const FilterState x = bodyState();
  PhotometricOptions po;
  int checked = 0;
  for (int level = 0; level < 3; ++level) {
    for (const Eigen::Vector3d& uvz : {Vec3(0.21, -0.13, 3.0), Vec3(-0.47, 0.36, 1.7)}) {
      TrackedPatch t;
      t.p_W = worldPoint(rig, x, uvz.x(), uvz.y(), uvz.z());
      Eigen::Vector2d u0;
      ASSERT_TRUE(cam.project(rig.T_I_C.inverse() * (x.rot.transpose() * (t.p_W - x.pos)), &u0));
      const Eigen::Vector2d ul = ImagePyramid::toLevel(u0, level);
      // the 10x10 window's shared bilinear fraction, away from cell borders so that the small
      // numeric steps stay inside one cell
      const double fx = ul.x() - 4.5 - std::floor(ul.x() - 4.5), fy = ul.y() - 4.5 - std::floor(ul.y() - 4.5);
      ASSERT_TRUE(fx > 0.05 && fx < 0.95 && fy > 0.05 && fy < 0.95) << fx << " " << fy;
      ImagePyramid pyr;
      const cv::Mat img = saddleImage(rig.width, rig.height, level, static_cast<int>(ul.x()), static_cast<int>(ul.y()));
      pyr.build(img, 3);
      // reference: the image at a shifted location, darker and offset (non-trivial residuals and gain)
      for (int j = 0; j < kPatch; ++j)
        for (int i = 0; i < kPatch; ++i)
          t.reference[static_cast<size_t>(level * kPatchArea + j * kPatch + i)] =
              0.8f * pyr.sample(level, ul.x() + i - 3.5 + 0.7, ul.y() + j - 3.5 - 0.4) + 12.0f;
      for (const bool affine : {true, false}) {
        po.affine_brightness = affine;
        PatchResidual e;
        ASSERT_TRUE(evaluatePatch(pyr, level, cam, rig.T_I_C, x, t, po, &e));
        if (affine) {
          EXPECT_NEAR(e.gain, 1.25, 0.15);  // the fitted gain undoes most of the darkening
        }
        EXPECT_GT(e.r.norm(), 5.0);
        const Eigen::Matrix<double, kPatchArea, 6> J = e.jacobian();
        // numeric: steps moving the patch by 0.01 level pixels
        const double h = 0.01 / (e.B.norm() / std::sqrt(6.0));
        Eigen::Matrix<double, kPatchArea, 6> N;
        for (int k = 0; k < 6; ++k) {
          Vec18 d = Vec18::Zero();
          d[k] = h;
          PatchResidual ep, em;
          ASSERT_TRUE(evaluatePatch(pyr, level, cam, rig.T_I_C, x.boxplus(d), t, po, &ep));
          ASSERT_TRUE(evaluatePatch(pyr, level, cam, rig.T_I_C, x.boxplus(-d), t, po, &em));
          N.col(k) = (ep.r - em.r) / (2 * h);
        }
        EXPECT_GT(N.norm(), 1.0);
        EXPECT_LT((J - N).norm() / N.norm(), 2e-3) << "affine " << affine << " level " << level;
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 12);
}

namespace {

// A rolling shutter reading 512 rows in 20 ms, the body turning at about 1.2 rad/s and moving at
// 1.5 m/s (brisk handheld motion).
RollingShutter brisk(const CameraRig& rig) {
  RollingShutter s = RollingShutter::fromReadout(0.02, rig.height);
  s.omega_I = Vec3(0.4, -0.9, 0.7);
  return s;
}

FilterState movingState() {
  FilterState x = bodyState();
  x.vel = Vec3(1.2, -0.6, 0.7);
  return x;
}

}  // namespace

TEST(VioRollingShutter, PointIsSeenFromThePoseOfItsRow) {
  const CameraRig rig = distortedCamera();
  const CameraProjection cam(rig);
  const FilterState x = movingState();
  const RollingShutter s = brisk(rig);
  EXPECT_DOUBLE_EQ(s.line_time, 0.02 / 512);
  EXPECT_DOUBLE_EQ(s.rowTime(255.5), 0.0);   // the stamp is the centre row's
  EXPECT_DOUBLE_EQ(s.rowTime(511.0), 255.5 * 0.02 / 512);  // the last row: half a readout (less half a line) later
  for (const Eigen::Vector3d& uvz : {Vec3(0.1, -0.5, 2.5), Vec3(-0.55, 0.4, 4.0), Vec3(0.6, 0.45, 1.2)}) {
    const Vec3 p_W = worldPoint(rig, x, uvz.x(), uvz.y(), uvz.z());
    ShutterProjection sp;
    ASSERT_TRUE(projectThroughShutter(cam, rig.T_I_C, x, s, p_W, &sp));
    // consistent: the row's pose sees the point at that very row
    const Pose3 T_W_C = cameraPoseAt(x, s, s.rowTime(sp.pixel.y()), rig.T_I_C);
    Eigen::Vector2d px;
    ASSERT_TRUE(cam.project(T_W_C.inverse() * p_W, &px));
    EXPECT_LT((px - sp.pixel).norm(), 0.01);
    // and far from where the stamp's pose sees it (rows away from the centre)
    Eigen::Vector2d px0;
    ASSERT_TRUE(cam.project((x.pose() * rig.T_I_C).inverse() * p_W, &px0));
    EXPECT_GT((px0 - sp.pixel).norm(), 0.5);
    // a global shutter is the stamp's projection
    ShutterProjection g;
    ASSERT_TRUE(projectThroughShutter(cam, rig.T_I_C, x, RollingShutter::fromReadout(0.0, rig.height), p_W, &g));
    EXPECT_LT((g.pixel - px0).norm(), 1e-9);
    EXPECT_EQ(g.dt, 0.0);
  }
}

TEST(VioRollingShutter, PixelJacobianWrtTheStampPoseMatchesNumeric) {
  const CameraRig rig = distortedCamera();
  const CameraProjection cam(rig);
  const FilterState x = movingState();
  const RollingShutter s = brisk(rig);
  const Pose3 T_C_I = rig.T_I_C.inverse();
  for (const Eigen::Vector3d& uvz : {Vec3(0.1, -0.5, 2.5), Vec3(-0.55, 0.4, 4.0), Vec3(0.6, 0.45, 1.2)}) {
    const Vec3 p_W = worldPoint(rig, x, uvz.x(), uvz.y(), uvz.z());
    ShutterProjection sp;
    ASSERT_TRUE(projectThroughShutter(cam, rig.T_I_C, x, s, p_W, &sp));
    ASSERT_GT(std::abs(sp.dt), 1e-3);
    const Mat26 B = pixelPoseJacobian(sp, s, rig.T_I_C);
    // the pixel of the pose at the row's time held fixed (the Jacobian's definition) ...
    auto atFixedRow = [&](const FilterState& y) {
      Eigen::Vector2d q;
      const Pose3 T_W_C = cameraPoseAt(y, s, sp.dt, rig.T_I_C);
      EXPECT_TRUE(cam.project(T_W_C.inverse() * p_W, &q));
      return q;
    };
    // ... and with the row following the pose (what the image sees)
    auto followingRow = [&](const FilterState& y) {
      ShutterProjection q;
      EXPECT_TRUE(projectThroughShutter(cam, rig.T_I_C, y, s, p_W, &q));
      return q.pixel;
    };
    const double h = 1e-7;
    for (int k = 0; k < 6; ++k) {
      Vec18 d = Vec18::Zero();
      d[k] = h;
      const Eigen::Vector2d fixed = (atFixedRow(x.boxplus(d)) - atFixedRow(x.boxplus(-d))) / (2 * h);
      const Eigen::Vector2d full = (followingRow(x.boxplus(d)) - followingRow(x.boxplus(-d))) / (2 * h);
      EXPECT_LT((B.col(k) - fixed).norm(), 1e-5 * (1.0 + fixed.norm())) << "column " << k;
      // the row's own motion is a few per cent at this rate
      EXPECT_LT((B.col(k) - full).norm(), 0.05 * full.norm()) << "column " << k;
    }
    // the global-shutter Jacobian at the stamp's pose differs from it by more than rounding
    Eigen::Matrix<double, 2, 3> J0;
    Eigen::Vector2d px0;
    const Vec3 p_I0 = x.rot.transpose() * (p_W - x.pos);
    ASSERT_TRUE(cam.projectWithJacobian(T_C_I * p_I0, &px0, &J0));
    EXPECT_GT((pixelPoseJacobian(J0, x.rot, rig.T_I_C, p_I0) - B).norm(), 1e-3 * B.norm());
  }
}

/// A moving, turning body behind a distorted rolling-shutter camera, over a flat grey pyramid (the
/// calibration Jacobians are about pixels, not intensities).
struct MovingCameraScene {
  CameraRig rig = distortedCamera();
  CameraProjection cam{rig};
  FilterState x = movingState();
  RollingShutter s = brisk(rig);
  ImagePyramid pyr;
  MovingCameraScene() { pyr.build(cv::Mat(rig.height, rig.width, CV_8UC1, cv::Scalar(100)), 3); }
};

TEST(VioJacobians, PixelJacobianWrtTheCameraExtrinsicMatchesNumeric) {
  // Bc = d pixel / d [φ ρ] for the extrinsic T_I_C (Exp(φ), ρ) (online calibration), with a
  // rolling shutter, at every level
  const MovingCameraScene scene;
  const auto& [rig, cam, x, s, pyr] = scene;
  auto withCorrection = [&](const Vec6& c) {
    return scene.rig.T_I_C * se3::fromRotationTranslation(so3::Exp(c.head<3>()), c.tail<3>());
  };
  for (int level = 0; level < 3; ++level)
    for (const Eigen::Vector3d& uvz : {Vec3(0.1, -0.3, 2.5), Vec3(-0.45, 0.3, 4.0)}) {
      TrackedPatch t;
      t.p_W = worldPoint(rig, x, uvz.x(), uvz.y(), uvz.z());
      PatchResidual e;
      ASSERT_TRUE(evaluatePatch(pyr, level, cam, rig.T_I_C, x, t, PhotometricOptions(), &e, s));
      const double h = 1e-7;
      for (int k = 0; k < 6; ++k) {
        Vec6 d = Vec6::Zero();
        d[k] = h;
        PatchResidual ep, em;
        ASSERT_TRUE(evaluatePatch(pyr, level, cam, withCorrection(d), x, t, PhotometricOptions(), &ep, s));
        ASSERT_TRUE(evaluatePatch(pyr, level, cam, withCorrection(-d), x, t, PhotometricOptions(), &em, s));
        const Eigen::Vector2d num = (ep.pixel - em.pixel) / (2 * h) / static_cast<double>(1 << level);
        // a radian turns the view by hundreds of pixels, a metre at a few metres moves it by tens
        EXPECT_GT(num.norm(), (k < 3 ? 50.0 : 10.0) / (1 << level));
        // the row time follows the pixel (a few per cent, as for the pose Jacobian)
        EXPECT_LT((e.Bc.col(k) - num).norm(), 0.05 * num.norm()) << "level " << level << " column " << k;
      }
    }
}

TEST(VioJacobians, PixelJacobianWrtTheImageTimeOffsetMatchesNumeric) {
  // the image taken at its stamp + δt sees the body at R Exp(ω δt), p + v δt: d pixel / d δt is
  // B [ω; v] (the δt column of the calibration information), checked against the pixel of the
  // advanced state
  const MovingCameraScene scene;
  const auto& [rig, cam, x, s, pyr] = scene;
  Vec6 motion;
  motion << s.omega_I, x.vel;
  ASSERT_GT(x.vel.norm(), 0.1);
  for (const Eigen::Vector3d& uvz : {Vec3(0.1, -0.3, 2.5), Vec3(-0.45, 0.3, 4.0)}) {
    TrackedPatch t;
    t.p_W = worldPoint(rig, x, uvz.x(), uvz.y(), uvz.z());
    PatchResidual e;
    ASSERT_TRUE(evaluatePatch(pyr, 0, cam, rig.T_I_C, x, t, PhotometricOptions(), &e, s));
    const double h = 1e-6;
    PatchResidual ep, em;
    ASSERT_TRUE(evaluatePatch(pyr, 0, cam, rig.T_I_C, advanced(x, s.omega_I, h), t, PhotometricOptions(), &ep, s));
    ASSERT_TRUE(evaluatePatch(pyr, 0, cam, rig.T_I_C, advanced(x, s.omega_I, -h), t, PhotometricOptions(), &em, s));
    const Eigen::Vector2d num = (ep.pixel - em.pixel) / (2 * h);
    const Eigen::Vector2d analytic = e.B * motion;
    EXPECT_GT(num.norm(), 20.0);  // pixels per second of the moving, turning view
    EXPECT_LT((analytic - num).norm(), 0.05 * num.norm());
  }
}
