#include "livo/plane.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace livo {

namespace {

// The least-squares plane and the scatter's eigen-decomposition (sums, not means; ascending).
bool fitScatter(const Vec3* pts, int n, PlaneFit* out, Eigen::SelfAdjointEigenSolver<Mat3>* es) {
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
  es->computeDirect(S);
  PlaneFit f;
  f.plane.normal = es->eigenvectors().col(0).normalized();
  f.plane.offset = -f.plane.normal.dot(c);
  f.centroid = c;
  f.spread = es->eigenvalues() / n;  // ascending
  if (!f.plane.normal.allFinite() || !f.spread.allFinite()) return false;
  *out = f;
  return true;
}

// Whether the set's in-plane spread is at least min_planarity of its largest with any one point
// left out. Without point i the scatter is S - n/(n-1) d_i d_i^T (d_i = p_i - centroid); its
// in-plane 2x2 block in S's eigenbasis has the eigenvalues compared here. A set that is a line
// plus one point off it (four floor points on one LiDAR ring and a wall point beside them) passes
// the whole-set test, yet its plane is that one point's choice. Three points have nothing to
// leave out: any three that are not collinear are a plane.
bool planarWithoutAnyOne(const Vec3* pts, int n, const PlaneFit& f, const Eigen::SelfAdjointEigenSolver<Mat3>& es,
                         double min_planarity) {
  if (n < 4) return true;
  const Vec3 e_mid = es.eigenvectors().col(1), e_max = es.eigenvectors().col(2);
  const double l_mid = es.eigenvalues()(1), l_max = es.eigenvalues()(2);
  const double w = static_cast<double>(n) / (n - 1);
  for (int i = 0; i < n; ++i) {
    const Vec3 d = pts[i] - f.centroid;
    const double a = e_mid.dot(d), b = e_max.dot(d);
    const double s11 = l_mid - w * a * a, s22 = l_max - w * b * b, s12 = -w * a * b;
    const double half_trace = 0.5 * (s11 + s22);
    const double root = std::sqrt(std::max(0.0, 0.25 * (s11 - s22) * (s11 - s22) + s12 * s12));
    if (!(half_trace - root > min_planarity * (half_trace + root))) return false;
  }
  return true;
}

}  // namespace

bool fitPlane(const Vec3* pts, int n, PlaneFit* out) {
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  return fitScatter(pts, n, out, &es);
}

bool fitPlane(const Vec3* pts, int n, double max_thickness, Plane* out, double min_planarity,
              bool* planar_without_any_one) {
  PlaneFit f;
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  if (!fitScatter(pts, n, &f, &es)) return false;
  // collinear or coincident neighbours fix no plane
  if (!(f.spread[1] > min_planarity * f.spread[2]) || !(f.spread[2] > 0.0)) return false;
  for (int i = 0; i < n; ++i)
    if (std::abs(f.plane.distance(pts[i])) > max_thickness) return false;
  if (planar_without_any_one) *planar_without_any_one = planarWithoutAnyOne(pts, n, f, es, min_planarity);
  *out = f.plane;
  return true;
}

}  // namespace livo
