#include "livo/colour/view_cone.hpp"

#include <Eigen/Geometry>
#include <algorithm>

namespace livo::colour {

void ViewCone::prepare() {
  // the shortcut's margin (1e-6 rad, a cosine margin of sin(angle) * 1e-6) dwarfs the rounding of
  // either test, so it only ever says "inside" where the exact test does
  constexpr double kMargin = 1e-6;
  if (half_angle - kMargin > 0.01 && half_angle - kMargin < M_PI - 0.01)
    cos_surely_inside = std::cos(half_angle - kMargin);
  const double outside = half_angle + std::asin(0.2) + kMargin;
  far_range = 5.0 * travel;
  if (outside > 0.01 && outside < M_PI - 0.01) cos_surely_outside = std::cos(outside);
  // half_angle + asin(s) <= pi - 0.01 for s < s_limit: cos(bound) falls with s there
  cos_half = std::cos(half_angle);
  sin_half = std::sin(half_angle);
  const double room = M_PI - 0.01 - half_angle;  // for asin(s)
  s_limit = half_angle < 0.0 ? 0.0 : room >= M_PI_2 ? 1.0 : room > 0.0 ? std::sin(room) : 0.0;
}

bool ViewCone::containsExactly(const Eigen::Vector3d& p) const {
  if (half_angle >= M_PI) return true;
  const Eigen::Vector3d v = p - centre;
  const double r = v.norm();
  if (r <= travel) return true;
  const double angle = std::atan2(v.cross(axis).norm(), v.dot(axis));
  return angle <= half_angle + std::asin(std::min(1.0, travel / r));
}

bool ViewCone::contains(const Eigen::Vector3d& p) const {
  if (half_angle >= M_PI) return true;
  const Eigen::Vector3d v = p - centre;
  const double r = v.norm();
  if (r <= travel) return true;
  const double along = v.dot(axis);
  if (along > cos_surely_inside * r) return true;                      // well inside
  if (r >= far_range && along < cos_surely_outside * r) return false;  // well outside
  const double s = travel / r;
  if (s < s_limit) {
    // (1 - s)(1 + s), not 1 - s^2: exact to an ulp even as s nears 1
    const double cos_bound = cos_half * std::sqrt((1.0 - s) * (1.0 + s)) - sin_half * s;
    const double c = along / r;
    if (c > cos_bound + kCosMargin) return true;
    if (c < cos_bound - kCosMargin) return false;
  }
  const double angle = std::atan2(v.cross(axis).norm(), along);
  return angle <= half_angle + std::asin(std::min(1.0, s));
}

}  // namespace livo::colour
