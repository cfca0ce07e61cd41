// Jacobians against numeric differentiation: the distorted projection (common
// CameraProjection), the pixel wrt the body pose error (right perturbation of W_R_I, W_p_I) and wrt
// the camera's calibration in the state (extrinsic and time shift), in the current image and in the
// reference image, and the photometric residual of a patch wrt all of them with the brightness fit
// projected out.
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
  for (const Eigen::Vector2d& xy :
       {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.41, -0.33), Eigen::Vector2d(-0.62, 0.47)}) {
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
      StateVector d = StateVector::Zero();
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

namespace {
// The error-state index of measured coordinate k (pose, then the camera's calibration block).
int measuredState(int k) { return k < 6 ? k : FilterState::kCamera + (k - 6); }

// A state with the rig's camera calibration turned a little and an image time shift, moving.
FilterState calibratedState(const CameraRig& rig) {
  FilterState x = bodyState();
  x.vel = Vec3(0.8, -0.4, 0.3);
  x.camera = SensorCalibration::fromPose(
      rig.T_I_C * se3::fromRotationTranslation(so3::Exp(Vec3(0.004, -0.003, 0.005)), Vec3(0.002, -0.001, 0.003)),
      0.004);
  return x;
}

// The view a reference patch of p_W was cut in: the body 0.4 m and a few degrees away, the patch
// centred where that image saw the point through a calibration a little off the state's.
ReferenceView referenceView(const CameraProjection& cam, const FilterState& x, const Vec3& p_W) {
  ReferenceView v;
  v.T_W_I = x.pose() * se3::fromRotationTranslation(so3::Exp(Vec3(0.03, -0.05, 0.04)), Vec3(-0.3, 0.2, 0.15));
  v.omega_I = Vec3(0.3, -0.5, 0.2);
  v.vel_W = Vec3(0.5, 0.1, -0.2);
  v.T_I_C = x.camera.pose() * se3::fromRotationTranslation(so3::Exp(Vec3(-0.002, 0.001, 0.002)), Vec3::Zero());
  v.time_shift = 0.001;
  EXPECT_TRUE(cam.project((v.T_W_I * v.T_I_C).inverse() * p_W, &v.pixel));
  return v;
}
}  // namespace

TEST(VioJacobians, PhotometricJacobianWrtTheStateMatchesNumeric) {
  // d r / d [δθ δp δφ δρ δdt]: the current image's gradient through the current pixel, and the
  // reference's through where the reference image sees the point with the state's calibration
  const CameraRig rig = distortedCamera();
  const CameraProjection cam(rig);
  const FilterState x = calibratedState(rig);
  PhotometricOptions po;
  int checked = 0;
  for (int level = 0; level < 3; ++level) {
    for (const Eigen::Vector3d& uvz : {Vec3(0.21, -0.13, 3.0), Vec3(-0.47, 0.36, 1.7)}) {
      // the camera when the image was taken: the stamp plus the time shift (no rotation rate here)
      const Pose3 T_W_C = advanced(x, Vec3::Zero(), x.camera.dt).pose() * x.camera.pose();
      TrackedPatch t;
      t.p_W = T_W_C * Vec3(uvz.x() * uvz.z(), uvz.y() * uvz.z(), uvz.z());
      Eigen::Vector2d u0;
      ASSERT_TRUE(cam.project(T_W_C.inverse() * t.p_W, &u0));
      const Eigen::Vector2d ul = ImagePyramid::toLevel(u0, level);
      // the 10x10 window's shared bilinear fraction, away from cell borders so that the small
      // numeric steps stay inside one cell
      const double fx = ul.x() - 4.5 - std::floor(ul.x() - 4.5), fy = ul.y() - 4.5 - std::floor(ul.y() - 4.5);
      if (!(fx > 0.05 && fx < 0.95 && fy > 0.05 && fy < 0.95)) continue;
      ImagePyramid pyr;
      const cv::Mat img = saddleImage(rig.width, rig.height, level, static_cast<int>(ul.x()), static_cast<int>(ul.y()));
      pyr.build(img, 3);
      t.view = referenceView(cam, x, t.p_W);
      Eigen::Vector2d u_ref;
      ASSERT_TRUE(projectIntoReference(cam, t.view, x.camera, t.p_W, &u_ref));
      t.shift0 = u_ref - t.view.pixel;
      // reference: the image, darker and offset, with its derivative along the shift; at a shifted
      // location (non-trivial residuals) with the offset fit alone, whose projection does not depend
      // on the reference, so the Jacobian is exact; at the point itself with the gain fitted too
      // (Kaufman's approximation drops a term in proportion to the residuals: none here)
      for (const bool affine : {true, false}) {
        const Eigen::Vector2d off = affine ? Eigen::Vector2d(0.0, 0.0) : Eigen::Vector2d(0.7, -0.4);
        for (int j = 0; j < kPatch; ++j)
          for (int i = 0; i < kPatch; ++i) {
            const size_t k = static_cast<size_t>(level * kPatchArea + j * kPatch + i);
            const double qx = ul.x() + i - 3.5 + off.x(), qy = ul.y() + j - 3.5 + off.y();
            t.reference[k] = 0.8f * pyr.sample(level, qx, qy) + 12.0f;
            t.reference_dx[k] = 0.8f * 0.5f * (pyr.sample(level, qx + 1.0, qy) - pyr.sample(level, qx - 1.0, qy));
            t.reference_dy[k] = 0.8f * 0.5f * (pyr.sample(level, qx, qy + 1.0) - pyr.sample(level, qx, qy - 1.0));
          }
        po.affine_brightness = affine;
        PatchResidual e;
        ASSERT_TRUE(evaluatePatch(pyr, level, cam, x, t, po, &e));
        if (affine) {
          EXPECT_NEAR(e.gain, 1.25, 0.01);  // the fitted gain undoes the darkening
          EXPECT_LT(e.r.norm(), 0.1);
        } else {
          EXPECT_GT(e.r.norm(), 5.0);
        }
        const Eigen::Matrix<double, kPatchArea, kMeasuredDim> J = e.jacobian();
        // numeric: steps moving the patch by 0.01 level pixels
        Eigen::Matrix<double, kPatchArea, kMeasuredDim> N;
        for (int k = 0; k < kMeasuredDim; ++k) {
          const double h = 0.01 / std::max(1e-3, e.B.col(k).norm());
          StateVector d = StateVector::Zero();
          d[measuredState(k)] = h;
          PatchResidual ep, em;
          ASSERT_TRUE(evaluatePatch(pyr, level, cam, x.boxplus(d), t, po, &ep));
          ASSERT_TRUE(evaluatePatch(pyr, level, cam, x.boxplus(-d), t, po, &em));
          N.col(k) = (ep.r - em.r) / (2 * h);
        }
        EXPECT_GT(N.norm(), 1.0);
        // the pose columns exactly; the calibration's only where the reference is aligned with the
        // image (the affine case): there the reference's gradient is the image's through the warp,
        // as the residual takes it (photometric_residual.hpp)
        for (int k = 0; k < (affine ? kMeasuredDim : 6); ++k)
          EXPECT_LT((J.col(k) - N.col(k)).norm(), 3e-3 * N.norm())
              << "affine " << affine << " level " << level << " column " << k;
        // the reference view moves with the calibration: its columns are not the current pixel's alone
        EXPECT_GT((e.G.rightCols<2>() * e.B.bottomRows<2>()).norm(), 0.01 * J.norm());
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, 8);
}

TEST(VioJacobians, ReferencePixelJacobianWrtTheCalibrationMatchesNumeric) {
  // the reference image's pixel of a map point through the state's extrinsic and time shift
  const CameraRig rig = distortedCamera();
  const CameraProjection cam(rig);
  const FilterState x = calibratedState(rig);
  for (const Eigen::Vector3d& uvz : {Vec3(0.21, -0.13, 3.0), Vec3(-0.47, 0.36, 1.7), Vec3(0.5, 0.4, 6.0)}) {
    const Vec3 p_W = worldPoint(rig, x, uvz.x(), uvz.y(), uvz.z());
    const ReferenceView v = referenceView(cam, x, p_W);
    Eigen::Vector2d px;
    Mat27 J;
    ASSERT_TRUE(projectIntoReference(cam, v, x.camera, p_W, &px, &J));
    // at the calibration it was cut through, the point is where the patch is centred
    Eigen::Vector2d at_cut;
    ASSERT_TRUE(projectIntoReference(cam, v, SensorCalibration::fromPose(v.T_I_C, v.time_shift), p_W, &at_cut));
    EXPECT_LT((at_cut - v.pixel).norm(), 1e-9);
    for (int k = 0; k < FilterState::kCalibrationDim; ++k) {
      const double h = 1e-7;
      StateVector d = StateVector::Zero();
      d[FilterState::kCamera + k] = h;
      Eigen::Vector2d a, b;
      ASSERT_TRUE(projectIntoReference(cam, v, x.boxplus(d).camera, p_W, &a));
      ASSERT_TRUE(projectIntoReference(cam, v, x.boxplus(-d).camera, p_W, &b));
      const Eigen::Vector2d num = (a - b) / (2 * h);
      EXPECT_GT(num.norm(), 1.0) << k;
      EXPECT_LT((J.col(k) - num).norm(), 1e-5 * (1.0 + num.norm())) << "column " << k;
    }
  }
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
  EXPECT_DOUBLE_EQ(s.rowTime(255.5), 0.0);                 // the stamp is the centre row's
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
      StateVector d = StateVector::Zero();
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

TEST(VioJacobians, PixelJacobianWrtTheCameraCalibrationMatchesNumeric) {
  // d pixel / d [δφ δρ δdt] of the current image: through the extrinsic, and the time shift moving
  // the body along its motion; global shutter (exact) and rolling shutter (the row follows the
  // pixel: a few per cent)
  const CameraRig rig = distortedCamera();
  const CameraProjection cam(rig);
  FilterState x = calibratedState(rig);
  for (const bool rolling : {false, true}) {
    RollingShutter s = rolling ? brisk(rig) : RollingShutter::fromReadout(0.0, rig.height);
    s.omega_I = brisk(rig).omega_I;
    for (const Eigen::Vector3d& uvz : {Vec3(0.1, -0.3, 2.5), Vec3(-0.45, 0.3, 4.0)}) {
      const Vec3 p_W = worldPoint(rig, x, uvz.x(), uvz.y(), uvz.z());
      auto pixelOf = [&](const FilterState& y) {
        ShutterProjection q;
        EXPECT_TRUE(projectThroughShutter(cam, y.camera.pose(), advanced(y, s.omega_I, y.camera.dt), s, p_W, &q));
        return q;
      };
      const ShutterProjection sp = pixelOf(x);
      const auto J = currentPixelJacobian(sp, s, x);
      for (int k = 0; k < kMeasuredDim; ++k) {
        const double h = 1e-7;
        StateVector d = StateVector::Zero();
        d[measuredState(k)] = h;
        const Eigen::Vector2d num = (pixelOf(x.boxplus(d)).pixel - pixelOf(x.boxplus(-d)).pixel) / (2 * h);
        EXPECT_GT(num.norm(), 1.0) << k;
        EXPECT_LT((J.col(k) - num).norm(), (rolling ? 0.05 : 1e-5) * (1.0 + num.norm()))
            << (rolling ? "rolling" : "global") << " column " << k;
      }
    }
  }
}
