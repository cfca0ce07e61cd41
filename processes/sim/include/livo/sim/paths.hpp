// Smooth paths p(s) with three exact derivatives in "path time" s: a closed quintic B-spline
// through a waypoint polygon (walks, drives) and a 3-D Lissajous figure (flights).
#pragma once

#include <vector>

#include "livo/so3.hpp"

namespace livo::sim {

struct PathSample {
  Vec3 p = Vec3::Zero();
  Vec3 d1 = Vec3::Zero(), d2 = Vec3::Zero(), d3 = Vec3::Zero();  // d^k p / ds^k
};

class Path {
 public:
  virtual ~Path() = default;
  virtual PathSample at(double s) const = 0;
};

/// Closed uniform quintic B-spline (C4). The waypoint polygon is resampled to control points
/// `control_spacing` metres apart, one per `control_spacing / speed` seconds: the path keeps
/// close to the polygon, rounds its corners, and slows down in them.
class BSplineLoopPath : public Path {
 public:
  BSplineLoopPath(const std::vector<Vec3>& waypoints, double speed, double control_spacing);
  PathSample at(double s) const override;
  double period() const { return knot_interval_ * static_cast<double>(control_.size()); }

 private:
  std::vector<Vec3> control_;
  double knot_interval_ = 1.0;
};

/// center + amplitude_i sin(2 pi f_i s + phase_i) per axis.
class LissajousPath : public Path {
 public:
  LissajousPath(const Vec3& center, const Vec3& amplitude, const Vec3& frequency_hz, const Vec3& phase_rad);
  PathSample at(double s) const override;

 private:
  Vec3 center_, amplitude_, omega_, phase_;
};

}  // namespace livo::sim
