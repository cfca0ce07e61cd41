#include "livo/camera_projection.hpp"

#include <algorithm>
#include <cmath>

namespace livo {

namespace {

/// theta_d(theta) = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8) and its derivative.
double equidistantThetaD(const std::array<double, 4>& k, double theta, double* dtheta_d = nullptr) {
  const double t2 = theta * theta;
  if (dtheta_d) *dtheta_d = 1.0 + t2 * (3.0 * k[0] + t2 * (5.0 * k[1] + t2 * (7.0 * k[2] + t2 * 9.0 * k[3])));
  return theta * (1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))));
}

constexpr double kSmallRadius = 1e-8;  // below it the equidistant model is the identity to 1e-16

}  // namespace

CameraProjection::CameraProjection(const CameraRig& rig) : rig_(rig) {
  // The valid field: the undistorted image corners, with a margin (radtan: a fixed-point inversion,
  // which stays where the polynomial is monotonic; equidistant: undistort's 1-D Newton on theta).
  double r2 = 0.0;
  const double corners[4][2] = {
      {0, 0}, {double(rig.width - 1), 0}, {0, double(rig.height - 1)}, {double(rig.width - 1), double(rig.height - 1)}};
  for (const auto& c : corners) {
    const Eigen::Vector2d d((c[0] - rig.cx) / rig.fx, (c[1] - rig.cy) / rig.fy);
    Eigen::Vector2d u = d;
    if (rig.distortion_model == DistortionModel::kEquidistant)
      u = undistort(d);
    else
      for (int it = 0; it < 50; ++it) u += d - distort(u);
    r2 = std::max(r2, u.squaredNorm());
  }
  max_r2_ = 1.5 * r2;
}

Eigen::Vector2d CameraProjection::distort(const Eigen::Vector2d& xy) const {
  const auto& k = rig_.distortion;
  if (rig_.distortion_model == DistortionModel::kEquidistant) {
    const double r = xy.norm();
    if (r < kSmallRadius) return xy;
    return xy * (equidistantThetaD(k, std::atan(r)) / r);
  }
  const double k1 = k[0], k2 = k[1], p1 = k[2], p2 = k[3];
  const double x = xy.x(), y = xy.y(), r2 = x * x + y * y;
  const double radial = 1.0 + k1 * r2 + k2 * r2 * r2;
  return {x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
          y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y};
}

bool CameraProjection::project(const Eigen::Vector3d& p_C, Eigen::Vector2d* pixel, double border) const {
  if (!(p_C.z() > 1e-6)) return false;
  const Eigen::Vector2d xy(p_C.x() / p_C.z(), p_C.y() / p_C.z());
  if (xy.squaredNorm() > max_r2_) return false;
  const Eigen::Vector2d d = distort(xy);
  *pixel = Eigen::Vector2d(rig_.fx * d.x() + rig_.cx, rig_.fy * d.y() + rig_.cy);
  return pixel->x() >= border && pixel->y() >= border && pixel->x() <= rig_.width - 1 - border &&
         pixel->y() <= rig_.height - 1 - border;
}

Eigen::Matrix2d CameraProjection::distortJacobian(const Eigen::Vector2d& xy) const {
  const auto& k = rig_.distortion;
  if (rig_.distortion_model == DistortionModel::kEquidistant) {
    // distort = s(r) xy with s = theta_d(atan r) / r: J = s I + s'(r) xy xy^T / r
    const double r = xy.norm();
    if (r < kSmallRadius) return Eigen::Matrix2d::Identity();
    double dtheta_d = 0.0;
    const double theta_d = equidistantThetaD(k, std::atan(r), &dtheta_d);
    const double s = theta_d / r;
    const double ds_dr = (dtheta_d / (1.0 + r * r) - s) / r;
    return s * Eigen::Matrix2d::Identity() + (ds_dr / r) * xy * xy.transpose();
  }
  const double k1 = k[0], k2 = k[1], p1 = k[2], p2 = k[3];
  const double x = xy.x(), y = xy.y(), r2 = x * x + y * y;
  const double radial = 1.0 + k1 * r2 + k2 * r2 * r2;
  const double dradial_dr2 = k1 + 2.0 * k2 * r2;  // d radial / d x = 2 x dradial_dr2
  Eigen::Matrix2d J;
  J(0, 0) = radial + 2.0 * x * x * dradial_dr2 + 2.0 * p1 * y + 6.0 * p2 * x;
  J(0, 1) = 2.0 * x * y * dradial_dr2 + 2.0 * p1 * x + 2.0 * p2 * y;
  J(1, 0) = J(0, 1);
  J(1, 1) = radial + 2.0 * y * y * dradial_dr2 + 6.0 * p1 * y + 2.0 * p2 * x;
  return J;
}

Eigen::Vector2d CameraProjection::undistort(const Eigen::Vector2d& distorted) const {
  if (rig_.distortion_model == DistortionModel::kEquidistant) {
    // radial: Newton on theta_d(theta) = |distorted| (as cv::fisheye::undistortPoints), then
    // r = tan(theta) along the same direction; theta stays below 90 degrees (in front of the camera)
    const double theta_d = distorted.norm();
    if (theta_d < kSmallRadius) return distorted;
    double theta = std::min(theta_d, 0.5 * M_PI - 1e-6);
    for (int it = 0; it < 20; ++it) {
      double slope = 0.0;
      const double f = equidistantThetaD(rig_.distortion, theta, &slope) - theta_d;
      if (std::abs(f) < 1e-15 || !(slope > 0.0)) break;
      theta = std::clamp(theta - f / slope, 0.0, 0.5 * M_PI - 1e-6);
    }
    return distorted * (std::tan(theta) / theta_d);
  }
  Eigen::Vector2d xy = distorted;
  for (int it = 0; it < 20; ++it) {
    const Eigen::Vector2d f = distort(xy) - distorted;
    if (f.squaredNorm() < 1e-24) break;
    xy -= distortJacobian(xy).inverse() * f;
  }
  return xy;
}

Eigen::Vector3d CameraProjection::pixelRay(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d d((pixel.x() - rig_.cx) / rig_.fx, (pixel.y() - rig_.cy) / rig_.fy);
  const Eigen::Vector2d xy = undistort(d);
  return Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized();
}

bool CameraProjection::projectWithJacobian(const Eigen::Vector3d& p_C, Eigen::Vector2d* pixel,
                                           Eigen::Matrix<double, 2, 3>* J, double border) const {
  if (!project(p_C, pixel, border)) return false;
  const double iz = 1.0 / p_C.z();
  const Eigen::Vector2d xy(p_C.x() * iz, p_C.y() * iz);
  Eigen::Matrix<double, 2, 3> dxy;  // d (x/z, y/z) / d p_C
  dxy << iz, 0.0, -xy.x() * iz, 0.0, iz, -xy.y() * iz;
  const Eigen::Matrix2d D = distortJacobian(xy);
  Eigen::Matrix2d K_D;
  K_D.row(0) = rig_.fx * D.row(0);
  K_D.row(1) = rig_.fy * D.row(1);
  *J = K_D * dxy;
  return true;
}

double CameraProjection::vignette(const Eigen::Vector2d& pixel, double v) const {
  if (v <= 0.0) return 1.0;
  const double half_diag2 = 0.25 * (double(rig_.width) * rig_.width + double(rig_.height) * rig_.height);
  const double dx = pixel.x() - rig_.cx, dy = pixel.y() - rig_.cy;
  return 1.0 - v * std::min(1.0, (dx * dx + dy * dy) / half_diag2);
}

}  // namespace livo
