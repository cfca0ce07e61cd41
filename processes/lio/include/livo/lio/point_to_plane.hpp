// Point-to-plane residuals (paper eq. 9) with the LiDAR's calibration in the state: a point q of the
// undistorted sweep in the LiDAR frame, its world image w seen from the body pose of the sweep's
// true end through the state's extrinsic, and a plane n^T x + d = 0 fitted to its nearest map
// neighbours. The sweep was undistorted with the LiDAR's time shift of the prior, dt0: each point
// moved along the IMU's motion from its stamp plus dt0 into the body frame at the state's time;
// what the state's dt says beyond that moves the whole sweep with the body's motion at its end:
//   w = R Exp(ω (dt - dt0)) (R_IL q + t_IL) + p + v (dt - dt0),   r = n^T w + d.
// (Moving the whole sweep by the end's rate alone, dt0 = 0, is a model of a time shift that holds
// only while the body's rate is the same over the sweep: a car's suspension rocks it at 1-5 Hz,
// half a period in a 100 ms sweep, and the shift then estimated was half the true one.)
#pragma once

#include "livo/esikf_update.hpp"
#include "livo/filter_state.hpp"
#include "livo/plane.hpp"
#include "livo/so3.hpp"

namespace livo::lio {

using Row6 = Eigen::Matrix<double, 1, 6>;
using Row13 = Eigen::Matrix<double, 1, kMeasuredDim>;

struct PlaneFitOptions {
  int num_neighbors = 5;               // k of the kNN search
  double max_neighbor_distance = 1.5;  // m, all k neighbours within this radius
  double max_plane_thickness = 0.03;   // m, every neighbour within this distance of the plane
  double min_planarity = 0.02;         // second over largest scatter eigenvalue: rejects the
                                       // nearly collinear neighbours of one far ring
};

/// The body pose of the sweep's true end, R Exp(ω (dt - dt0)) and p + v (dt - dt0) (ω: the body
/// rate, frame I; dt0: the time shift the sweep was undistorted with).
inline Pose3 sweepEndPose(const FilterState& x, const Vec3& body_rate, double undistorted_dt) {
  const double dt = x.lidar.dt - undistorted_dt;
  return se3::fromRotationTranslation(dt != 0.0 ? Mat3(x.rot * so3::Exp(body_rate * dt)) : x.rot, x.pos + x.vel * dt);
}

struct PointToPlaneResidual {
  Vec3 q_lidar;  // point in the LiDAR frame at the sweep end
  Plane plane;   // world frame

  /// r at state x; `end` = sweepEndPose(x, body_rate, dt0).
  double value(const FilterState& x, const Pose3& end) const {
    return plane.distance(end * (x.lidar.rot * q_lidar + x.lidar.pos));
  }
  /// ∂r/∂[δθ δp δφ δρ δdt] (MeasurementInformation's order, calibration block FilterState::kLidar):
  /// with p_I = R_IL q + t_IL and n_I = R_end^T n,
  ///   [(p_I x n_I)^T, n^T, (q x R_IL^T n_I)^T, n_I^T, n_I . (ω x p_I) + n . v].
  /// (The rotation columns take Exp(ω dt) as commuting with the perturbation: dt is milliseconds.)
  Row13 jacobian(const FilterState& x, const Pose3& end, const Vec3& body_rate) const {
    const Vec3& n = plane.normal;
    const Vec3 n_I = end.linear().transpose() * n;
    const Vec3 p_I = x.lidar.rot * q_lidar + x.lidar.pos;
    Row13 J;
    J.segment<3>(0) = p_I.cross(n_I).transpose();
    J.segment<3>(3) = n.transpose();
    J.segment<3>(6) = q_lidar.cross(x.lidar.rot.transpose() * n_I).transpose();
    J.segment<3>(9) = n_I.transpose();
    J[12] = n_I.dot(body_rate.cross(p_I)) + n.dot(x.vel);
    return J;
  }
};

}  // namespace livo::lio
