// Point-to-plane residuals (paper eq. 9): a body point p, its world image R p + t and a plane
// n^T x + d = 0 fitted to its nearest map neighbours; r = n^T (R p + t) + d.
#pragma once

#include "livo/plane.hpp"
#include "livo/so3.hpp"

namespace livo::lio {

using Row6 = Eigen::Matrix<double, 1, 6>;

struct PlaneFitOptions {
  int num_neighbors = 5;              // k of the kNN search
  double max_neighbor_distance = 1.5; // m, all k neighbours within this radius
  double max_plane_thickness = 0.03;  // m, every neighbour within this distance of the plane
  double min_planarity = 0.02;        // second over largest scatter eigenvalue: rejects the
                                      // nearly collinear neighbours of one far ring
};

struct PointToPlaneResidual {
  Vec3 p_body;  // point in the body frame I
  Plane plane;  // world frame

  double value(const Mat3& R, const Vec3& t) const { return plane.distance(R * p_body + t); }
  /// ∂r/∂[δr δp] with x ⊞ δ = (R Exp(δr), t + δp): [-(n^T R [p]x), n^T].
  Row6 jacobian(const Mat3& R) const {
    Row6 J;
    J.head<3>() = (p_body.cross(R.transpose() * plane.normal)).transpose();
    J.tail<3>() = plane.normal.transpose();
    return J;
  }
};

}  // namespace livo::lio
