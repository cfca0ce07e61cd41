#include "livo/sim/paths.hpp"

#include <cmath>
#include <stdexcept>

namespace livo::sim {

namespace {
constexpr int kDegree = 5;

/// de Boor on a window of degree+1 control points of a uniform B-spline, local parameter u in [0, 1).
Vec3 deBoor(Vec3* P, int degree, double u) {
  const double x = degree + u;
  for (int r = 1; r <= degree; ++r)
    for (int j = degree; j >= r; --j) {
      const double alpha = (x - j) / (degree + 1 - r);
      P[j] = (1.0 - alpha) * P[j - 1] + alpha * P[j];
    }
  return P[degree];
}
}  // namespace

BSplineLoopPath::BSplineLoopPath(const std::vector<Vec3>& waypoints, double speed, double spacing) {
  if (waypoints.size() < 3) throw std::invalid_argument("a closed path needs at least 3 waypoints");
  if (!(speed > 0.0) || !(spacing > 0.0)) throw std::invalid_argument("speed and control spacing must be > 0");
  for (size_t i = 0; i < waypoints.size(); ++i) {
    const Vec3& a = waypoints[i];
    const Vec3& b = waypoints[(i + 1) % waypoints.size()];
    const int n = std::max(1, static_cast<int>(std::round((b - a).norm() / spacing)));
    for (int k = 0; k < n; ++k) control_.push_back(a + (b - a) * (static_cast<double>(k) / n));
  }
  if (control_.size() < kDegree + 1) throw std::invalid_argument("path too short for its control spacing");
  knot_interval_ = spacing / speed;
}

PathSample BSplineLoopPath::at(double s) const {
  const int n = static_cast<int>(control_.size());
  // shift so that s = 0 lies near the first waypoint (the window centre is 2.5 points ahead)
  const double x = s / knot_interval_ - 0.5 * kDegree + 2.0 * n;
  double fl = std::floor(x);
  const double u = x - fl;
  const int64_t seg = static_cast<int64_t>(fl);
  Vec3 window[kDegree + 1];
  for (int k = 0; k <= kDegree; ++k) window[k] = control_[static_cast<size_t>(((seg + k) % n + n) % n)];
  PathSample out;
  Vec3 tmp[kDegree + 1];
  Vec3* derivs[4] = {&out.p, &out.d1, &out.d2, &out.d3};
  double scale = 1.0;
  for (int m = 0; m <= 3; ++m) {
    // window of the m-th derivative: m-th forward differences, degree 5 - m
    for (int k = 0; k <= kDegree - m; ++k) tmp[k] = window[k];
    *derivs[m] = deBoor(tmp, kDegree - m, u) * scale;
    for (int k = 0; k < kDegree - m; ++k) window[k] = window[k + 1] - window[k];
    scale /= knot_interval_;
  }
  return out;
}

LissajousPath::LissajousPath(const Vec3& center, const Vec3& amplitude, const Vec3& frequency_hz, const Vec3& phase_rad)
    : center_(center), amplitude_(amplitude), omega_(2.0 * M_PI * frequency_hz), phase_(phase_rad) {}

PathSample LissajousPath::at(double s) const {
  PathSample out;
  for (int i = 0; i < 3; ++i) {
    const double w = omega_[i], a = amplitude_[i];
    const double sn = std::sin(w * s + phase_[i]), cs = std::cos(w * s + phase_[i]);
    out.p[i] = center_[i] + a * sn;
    out.d1[i] = a * w * cs;
    out.d2[i] = -a * w * w * sn;
    out.d3[i] = -a * w * w * w * cs;
  }
  return out;
}

}  // namespace livo::sim
