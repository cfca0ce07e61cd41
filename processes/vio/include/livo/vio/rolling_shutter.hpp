// Rolling-shutter projection: row v of an image is exposed at
//   t(v) = stamp + line_time · (v − (rows − 1) / 2)
// (the stamp is the centre row's, rig.camera.rolling_shutter_s = line_time · rows), so a world
// point is seen from the body pose at the time of the row it lands on. The pose at stamp + dt is
// the state's, moved with its velocity and the body's angular rate:
//   R(dt) = R Exp(ω dt),  p(dt) = p + v dt.
// The row depends on the pose and the pose on the row: a fixed-point iteration from the stamp's
// projection converges geometrically (the row moves by |du/dt| · line_time per row, a few
// hundredths at handheld rates), two steps leave well under a hundredth of a pixel.
// A zero line time is the global shutter: the stamp's pose for every row.
#pragma once

#include <Eigen/Core>

#include "livo/camera_projection.hpp"
#include "livo/filter_state.hpp"

namespace livo::vio {

struct RollingShutter {
  double line_time = 0.0;       // s per row (0: global shutter)
  double centre_row = 0.0;      // (rows − 1) / 2, the row the stamp refers to
  Vec3 omega_I = Vec3::Zero();  // body angular rate, rad/s (frame I)

  /// From the rig's readout time (first to last row) and image height; no motion yet.
  static RollingShutter fromReadout(double readout_s, int rows);
  bool active() const { return line_time > 0.0; }
  /// Time of row v relative to the stamp, s.
  double rowTime(double v) const { return line_time * (v - centre_row); }
  /// Body rotation from the stamp to stamp + dt, Exp(ω dt).
  Mat3 rotationSince(double dt) const;
};

/// Where a world point is seen, with the pose it is seen from.
struct ShutterProjection {
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  Eigen::Matrix<double, 2, 3> J_proj = Eigen::Matrix<double, 2, 3>::Zero();  // d pixel / d p_C
  double dt = 0.0;                                                           // row time relative to the stamp
  Mat3 R_W_I = Mat3::Identity();                                             // body pose at the row's time
  Vec3 p_W_I = Vec3::Zero();
  Vec3 p_I = Vec3::Zero();  // the point in that body frame
  Vec3 p_C = Vec3::Zero();  // ... and in the camera frame
};

/// Projects p_W from the body state x (at the stamp) through a rolling shutter; false if it does
/// not project (`border` as in CameraProjection::project). Without `with_jacobian` J_proj is left
/// as it was (the map maintenance only needs where points are seen).
bool projectThroughShutter(const CameraProjection& camera, const Pose3& T_I_C, const FilterState& x,
                           const RollingShutter& shutter, const Vec3& p_W, ShutterProjection* out, double border = 0.0,
                           bool with_jacobian = true);

/// The camera pose W_T_C at which a point seen at row time dt was captured.
/// The state moved forward by dt at the body rate omega_I and its velocity (dt of a few ms:
/// constant rate and velocity): R Exp(ω dt), p + v dt.
FilterState advanced(const FilterState& x, const Vec3& omega_I, double dt);

Pose3 cameraPoseAt(const FilterState& x, const RollingShutter& shutter, double dt, const Pose3& T_I_C);

}  // namespace livo::vio
