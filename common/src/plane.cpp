#include "livo/plane.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace livo {

bool fitPlane(const Vec3* pts, int n, PlaneFit* out) {
  if (n < 3) return false;
  Vec3 c = Vec3::Zero();
  for (int i = 0; i < n; ++i) c += pts[i];
  c /= n;
  // the scatter's six distinct sums (as S += d d^T would add them, without its 3x3 temporaries)
  double sxx = 0.0, sxy = 0.0, sxz = 0.0, syy = 0.0, syz = 0.0, szz = 0.0;
  for (int i = 0; i < n; ++i) {
    const Vec3 d = pts[i] - c;
    sxx += d.x() * d.x(), sxy += d.x() * d.y(), sxz += d.x() * d.z();
    syy += d.y() * d.y(), syz += d.y() * d.z(), szz += d.z() * d.z();
  }
  Mat3 S;
  S << sxx, sxy, sxz, sxy, syy, syz, sxz, syz, szz;
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  es.computeDirect(S);
  PlaneFit f;
  f.plane.normal = es.eigenvectors().col(0).normalized();
  f.plane.offset = -f.plane.normal.dot(c);
  f.centroid = c;
  f.spread = es.eigenvalues() / n;  // ascending
  if (!f.plane.normal.allFinite() || !f.spread.allFinite()) return false;
  *out = f;
  return true;
}

bool fitPlane(const Vec3* pts, int n, double max_thickness, Plane* out, double min_planarity) {
  PlaneFit f;
  if (!fitPlane(pts, n, &f)) return false;
  // collinear or coincident neighbours fix no plane
  if (!(f.spread[1] > min_planarity * f.spread[2]) || !(f.spread[2] > 0.0)) return false;
  for (int i = 0; i < n; ++i)
    if (std::abs(f.plane.distance(pts[i])) > max_thickness) return false;
  *out = f.plane;
  return true;
}

}  // namespace livo
