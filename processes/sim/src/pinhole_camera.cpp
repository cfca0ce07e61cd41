#include "livo/sim/pinhole_camera.hpp"

namespace livo::sim {

PinholeCamera::PinholeCamera(const CameraRig& rig) : rig_(rig) {}

Eigen::Vector2d PinholeCamera::distort(const Eigen::Vector2d& n) const {
  const double k1 = rig_.distortion[0], k2 = rig_.distortion[1], p1 = rig_.distortion[2], p2 = rig_.distortion[3];
  const double x = n.x(), y = n.y(), r2 = x * x + y * y;
  const double radial = 1.0 + k1 * r2 + k2 * r2 * r2;
  return Eigen::Vector2d(x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
                         y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y);
}

Eigen::Vector2d PinholeCamera::undistort(const Eigen::Vector2d& d) const {
  // Newton iterations on distort(n) = d with a numeric Jacobian
  Eigen::Vector2d n = d;
  for (int it = 0; it < 20; ++it) {
    const Eigen::Vector2d f = distort(n) - d;
    if (f.norm() < 1e-14) break;
    const double h = 1e-7;
    Eigen::Matrix2d J;
    J.col(0) = (distort(n + Eigen::Vector2d(h, 0.0)) - distort(n - Eigen::Vector2d(h, 0.0))) / (2.0 * h);
    J.col(1) = (distort(n + Eigen::Vector2d(0.0, h)) - distort(n - Eigen::Vector2d(0.0, h))) / (2.0 * h);
    n -= J.inverse() * f;
  }
  return n;
}

bool PinholeCamera::project(const Vec3& p, Eigen::Vector2d* pixel) const {
  if (p.z() <= 1e-9) return false;
  const Eigen::Vector2d d = distort(Eigen::Vector2d(p.x() / p.z(), p.y() / p.z()));
  *pixel = Eigen::Vector2d(rig_.fx * d.x() + rig_.cx, rig_.fy * d.y() + rig_.cy);
  return true;
}

Vec3 PinholeCamera::pixelRay(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d d((pixel.x() - rig_.cx) / rig_.fx, (pixel.y() - rig_.cy) / rig_.fy);
  const Eigen::Vector2d n = undistort(d);
  return Vec3(n.x(), n.y(), 1.0).normalized();
}

}  // namespace livo::sim
