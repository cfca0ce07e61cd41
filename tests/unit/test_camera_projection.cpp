// The camera model (CameraProjection), radial-tangential and equidistant: projection and
// undistortion against OpenCV (cv::projectPoints / undistortPoints, cv::fisheye), Jacobians
// against central differences, and undistort(distort(x)) round trips over the image's field (for
// the fisheye, the part within 80 degrees of the axis).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "livo/camera_projection.hpp"

using namespace livo;

namespace {

/// EuRoC MAV cam0 (radial-tangential).
CameraRig radtanRig() {
  CameraRig c;
  c.width = 752;
  c.height = 480;
  c.fx = 458.654;
  c.fy = 457.296;
  c.cx = 367.215;
  c.cy = 248.375;
  c.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  return c;
}

/// TUM-VI cam0 (equidistant, a fisheye of about 190 degrees).
CameraRig equidistantRig() {
  CameraRig c;
  c.width = c.height = 512;
  c.fx = 190.97847715128717;
  c.fy = 190.9733070521226;
  c.cx = 254.93170605935475;
  c.cy = 256.8974428996504;
  c.distortion_model = DistortionModel::kEquidistant;
  c.distortion = {0.0034823894022493434, 0.0007150348452162257, -0.0020532361418706202, 0.00020293673591811182};
  return c;
}

std::vector<CameraRig> bothModels() { return {radtanRig(), equidistantRig()}; }

/// Whether a pixel looks less than 80 degrees off the optical axis: the part of a fisheye's field
/// (TUM-VI's reaches 95 degrees in the corners) that a pinhole's normalised coordinates can hold.
bool withinPinholeField(const CameraProjection& camera, const Eigen::Vector2d& px) {
  return camera.pixelRay(px).z() > std::cos(80.0 * M_PI / 180.0);
}

/// Points in front of the camera that project into the image: pixels spread over it (nearly to
/// the corners), their rays at random depths.
std::vector<Eigen::Vector3d> pointsInView(const CameraProjection& camera, std::vector<Eigen::Vector2d>* pixels) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> depth(0.5, 20.0);
  const CameraRig& r = camera.rig();
  std::vector<Eigen::Vector3d> points;
  for (int v = 0; v < r.height; v += 23)
    for (int u = 0; u < r.width; u += 29) {
      const Eigen::Vector2d px(u + 0.37, v + 0.61);
      if (!withinPinholeField(camera, px)) continue;
      pixels->push_back(px);
      points.push_back(camera.pixelRay(px) * depth(rng));
    }
  for (const Eigen::Vector2d& px : {Eigen::Vector2d(0.01, 0.01), Eigen::Vector2d(r.width - 1.01, r.height - 1.01)}) {
    if (!withinPinholeField(camera, px)) continue;
    pixels->push_back(px);
    points.push_back(camera.pixelRay(px) * 2.0);
  }
  return points;
}

/// OpenCV's pixels of points (camera frame), by the rig's model.
std::vector<cv::Point2d> openCvProject(const CameraRig& r, const std::vector<Eigen::Vector3d>& points) {
  const cv::Matx33d K(r.fx, 0, r.cx, 0, r.fy, r.cy, 0, 0, 1);
  const cv::Vec4d D(r.distortion[0], r.distortion[1], r.distortion[2], r.distortion[3]);
  std::vector<cv::Point3d> pts;
  for (const auto& p : points) pts.emplace_back(p.x(), p.y(), p.z());
  std::vector<cv::Point2d> px;
  if (r.distortion_model == DistortionModel::kEquidistant)
    cv::fisheye::projectPoints(pts, px, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D);
  else
    cv::projectPoints(pts, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, px);
  return px;
}

}  // namespace

TEST(CameraProjection, ProjectionMatchesOpenCvForBothModels) {
  for (const CameraRig& rig : bothModels()) {
    SCOPED_TRACE(distortionModelName(rig.distortion_model));
    const CameraProjection camera(rig);
    std::vector<Eigen::Vector2d> pixels;
    const std::vector<Eigen::Vector3d> points = pointsInView(camera, &pixels);
    const std::vector<cv::Point2d> cv_px = openCvProject(rig, points);
    double worst = 0.0;
    for (size_t i = 0; i < points.size(); ++i) {
      Eigen::Vector2d px;
      ASSERT_TRUE(camera.project(points[i], &px)) << "pixel " << pixels[i].transpose();
      worst = std::max(worst, (px - Eigen::Vector2d(cv_px[i].x, cv_px[i].y)).norm());
      EXPECT_NEAR((px - pixels[i]).norm(), 0.0, 1e-6) << "pixelRay then project returns to " << pixels[i].transpose();
    }
    EXPECT_LT(worst, 1e-6) << "largest difference to OpenCV, px";
  }
}

TEST(CameraProjection, UndistortionMatchesOpenCvForBothModels) {
  for (const CameraRig& rig : bothModels()) {
    SCOPED_TRACE(distortionModelName(rig.distortion_model));
    const CameraProjection camera(rig);
    const cv::Matx33d K(rig.fx, 0, rig.cx, 0, rig.fy, rig.cy, 0, 0, 1);
    const cv::Vec4d D(rig.distortion[0], rig.distortion[1], rig.distortion[2], rig.distortion[3]);
    std::vector<cv::Point2d> px;
    for (int v = 0; v < rig.height; v += 31)
      for (int u = 0; u < rig.width; u += 37)
        if (withinPinholeField(camera, Eigen::Vector2d(u, v))) px.emplace_back(u, v);
    ASSERT_GT(px.size(), 150u);
    std::vector<cv::Point2d> xy;
    const cv::TermCriteria tight(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-14);
    if (rig.distortion_model == DistortionModel::kEquidistant)
      cv::fisheye::undistortPoints(px, xy, K, D, cv::noArray(), cv::noArray(), tight);
    else
      cv::undistortPoints(px, xy, K, D, cv::noArray(), cv::noArray(), tight);
    for (size_t i = 0; i < px.size(); ++i) {
      const Eigen::Vector2d d((px[i].x - rig.cx) / rig.fx, (px[i].y - rig.cy) / rig.fy);
      const Eigen::Vector2d mine = camera.undistort(d);
      // compared as pixels of an undistorted camera with the same focal length
      EXPECT_LT(rig.fx * (mine - Eigen::Vector2d(xy[i].x, xy[i].y)).norm(), 1e-6) << px[i];
    }
  }
}

TEST(CameraProjection, JacobiansMatchCentralDifferences) {
  for (const CameraRig& rig : bothModels()) {
    SCOPED_TRACE(distortionModelName(rig.distortion_model));
    const CameraProjection camera(rig);
    std::vector<Eigen::Vector2d> pixels;
    const std::vector<Eigen::Vector3d> points = pointsInView(camera, &pixels);
    for (const Eigen::Vector3d& p : points) {
      Eigen::Vector2d px;
      Eigen::Matrix<double, 2, 3> J;
      if (!camera.projectWithJacobian(p, &px, &J, 1.0)) continue;  // a border for the differences
      const double h = 1e-6 * p.norm();
      Eigen::Matrix<double, 2, 3> numeric;
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d dp = Eigen::Vector3d::Zero();
        dp[k] = h;
        Eigen::Vector2d plus, minus;
        ASSERT_TRUE(camera.project(p + dp, &plus) && camera.project(p - dp, &minus));
        numeric.col(k) = (plus - minus) / (2.0 * h);
      }
      EXPECT_LT((J - numeric).norm(), 1e-5 * std::max(1.0, numeric.norm())) << p.transpose();
      const Eigen::Vector2d xy(p.x() / p.z(), p.y() / p.z());
      Eigen::Matrix2d Dn;
      for (int k = 0; k < 2; ++k) {
        Eigen::Vector2d e = Eigen::Vector2d::Zero();
        e[k] = 1e-7;
        Dn.col(k) = (camera.distort(xy + e) - camera.distort(xy - e)) / 2e-7;
      }
      EXPECT_LT((camera.distortJacobian(xy) - Dn).norm(), 1e-7 * std::max(1.0, Dn.norm())) << xy.transpose();
    }
    // on the optical axis, where the equidistant model divides by the radius
    const Eigen::Matrix2d J0 = camera.distortJacobian(Eigen::Vector2d::Zero());
    EXPECT_LT((J0 - Eigen::Matrix2d::Identity()).norm(), 1e-12);
    EXPECT_LT((camera.distort(Eigen::Vector2d(1e-9, -2e-9)) - Eigen::Vector2d(1e-9, -2e-9)).norm(), 1e-15);
  }
}

TEST(CameraProjection, UndistortInvertsDistortOverTheField) {
  for (const CameraRig& rig : bothModels()) {
    SCOPED_TRACE(distortionModelName(rig.distortion_model));
    const CameraProjection camera(rig);
    double worst_image = 0.0, worst_normalised = 0.0;
    for (int v = 0; v < rig.height; v += 7)
      for (int u = 0; u < rig.width; u += 7) {
        if (!withinPinholeField(camera, Eigen::Vector2d(u, v))) continue;
        const Eigen::Vector2d d((u - rig.cx) / rig.fx, (v - rig.cy) / rig.fy);
        const Eigen::Vector2d xy = camera.undistort(d);
        worst_image = std::max(worst_image, rig.fx * (camera.distort(xy) - d).norm());
        worst_normalised =
            std::max(worst_normalised, (camera.undistort(camera.distort(xy)) - xy).norm() / (1.0 + xy.norm()));
      }
    EXPECT_LT(worst_image, 1e-8) << "distort(undistort(d)) - d, px";
    EXPECT_LT(worst_normalised, 1e-9) << "undistort(distort(xy)) - xy, relative";
  }
}

TEST(CameraProjection, RefusesPointsBehindOrOutsideTheField) {
  for (const CameraRig& rig : bothModels()) {
    SCOPED_TRACE(distortionModelName(rig.distortion_model));
    const CameraProjection camera(rig);
    Eigen::Vector2d px;
    EXPECT_FALSE(camera.project(Eigen::Vector3d(0.1, 0.1, -1.0), &px));
    EXPECT_FALSE(camera.project(Eigen::Vector3d(1.0, 0.0, 0.0), &px));
    EXPECT_FALSE(camera.project(Eigen::Vector3d(100.0, 0.0, 1.0), &px)) << "far outside the image";
    EXPECT_TRUE(camera.project(Eigen::Vector3d(0.0, 0.0, 1.0), &px));
    EXPECT_NEAR(px.x(), rig.cx, 1e-12);
    EXPECT_NEAR(px.y(), rig.cy, 1e-12);
  }
}
