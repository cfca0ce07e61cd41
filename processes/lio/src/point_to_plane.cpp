#include "livo/lio/point_to_plane.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace livo::lio {

bool fitPlane(const Vec3* pts, int n, double max_thickness, Plane* out, double min_planarity) {
  if (n < 3) return false;
  Vec3 c = Vec3::Zero();
  for (int i = 0; i < n; ++i) c += pts[i];
  c /= n;
  Mat3 S = Mat3::Zero();
  for (int i = 0; i < n; ++i) {
    const Vec3 d = pts[i] - c;
    S += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Mat3> es;
  es.computeDirect(S);
  const Vec3 ev = es.eigenvalues();  // ascending
  // collinear or coincident neighbours fix no plane
  if (!(ev[1] > min_planarity * ev[2]) || !(ev[2] > 0.0)) return false;
  Plane p;
  p.normal = es.eigenvectors().col(0).normalized();
  p.offset = -p.normal.dot(c);
  if (!p.normal.allFinite()) return false;
  for (int i = 0; i < n; ++i)
    if (std::abs(p.distance(pts[i])) > max_thickness) return false;
  *out = p;
  return true;
}

}  // namespace livo::lio
