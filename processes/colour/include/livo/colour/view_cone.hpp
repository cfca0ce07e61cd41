// The cone around the camera's axis at a scan pose within which an image of the scan's time window
// may see a point (see ColourOptions::view_margin_deg): a point at range r from the centre is inside
// if r <= travel or if its angle to the axis is at most half_angle + asin(travel / r).
#pragma once

#include <cmath>

#include <Eigen/Core>

namespace livo::colour {

struct ViewCone {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero(), axis = Eigen::Vector3d::UnitZ();
  double half_angle = M_PI;  // rad, before the travel term
  double travel = 0.0;       // m: how far the camera may move over the window

  /// Sets the shortcuts below from centre, axis, half_angle and travel; call it after setting them.
  void prepare();
  /// The test, decided without trigonometry for all but a sliver of points, always as
  /// containsExactly() decides (tests/colour: ViewCone.*).
  bool contains(const Eigen::Vector3d& p) const;
  /// The test as defined: an atan2 and an asin a point.
  bool containsExactly(const Eigen::Vector3d& p) const;

  // Shortcuts past the exact test: a point whose angle's cosine is above cos_surely_inside
  // (cos(half_angle - 1e-6); 2: none) is inside, one at least far_range (5 travel) away whose
  // cosine is below cos_surely_outside (cos(half_angle + asin(0.2) + 1e-6), asin(0.2) bounding the
  // travel term there; -2: none) is outside, whatever the rounding of either test. Between them,
  // the bound's cosine at the point's range, cos(half_angle + asin(s)) = cos_half sqrt(1 - s^2) -
  // sin_half s with s = travel / r, decides unless the point's cosine lies within kCosMargin of it
  // or the bound comes within 0.01 rad of pi (s >= s_limit), where the cosine stops falling.
  double cos_surely_inside = 2.0;
  double cos_surely_outside = -2.0;
  double far_range = 0.0;
  double cos_half = -1.0, sin_half = 0.0;
  double s_limit = 0.0;  // 0: the exact test for every point not decided above
  // |cos a - cos b| <= |a - b|: a point's cosine this far from the bound's is 1e-7 rad or more from
  // it in angle, where the rounding of either test is below 1e-14 rad
  static constexpr double kCosMargin = 1e-7;
};

}  // namespace livo::colour
