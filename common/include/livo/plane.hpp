// Planes in 3D: the least-squares plane of a point set (the smallest eigenvector of its scatter),
// shared by the LIO's point-to-plane matching and the VIO's map-point denoising.
#pragma once

#include "livo/so3.hpp"

namespace livo {

struct Plane {
  Vec3 normal = Vec3::UnitZ();  // unit
  double offset = 0.0;          // d in n^T x + d = 0
  double distance(const Vec3& x) const { return normal.dot(x) + offset; }
  /// x moved along the normal onto the plane.
  Vec3 project(const Vec3& x) const { return x - distance(x) * normal; }
};

/// The least-squares plane of a point set and the shape of the set around it.
struct PlaneFit {
  Plane plane;
  Vec3 centroid = Vec3::Zero();
  Vec3 spread = Vec3::Zero();  // eigenvalues of the scatter / n, ascending: spread[0] is the mean
                               // squared distance to the plane, spread[1] the weaker in-plane one
};

/// Least-squares plane through n >= 3 points; false for fewer points or a non-finite result.
bool fitPlane(const Vec3* points, int n, PlaneFit* out);

/// Least-squares plane through n >= 3 points. Returns false if the points are (nearly) collinear
/// — the scatter's second eigenvalue below min_planarity times the largest — or one lies farther
/// than max_thickness. No default: the callers' options say how planar (the LIO's
/// `matching.plane.min_planarity`). If planar_without_any_one is given, it says whether the set
/// stays that planar with any one point left out: a line plus one point beside it (four floor
/// points along one LiDAR ring and a wall point) spans a plane that one point chose. Such a plane
/// may still be right (four points of one ring on a wall and one of the next), so it is not
/// rejected here; the LIO does not count it as evidence that its direction is observed.
bool fitPlane(const Vec3* points, int n, double max_thickness, Plane* out, double min_planarity,
              bool* planar_without_any_one = nullptr);

}  // namespace livo
