// Where a reference image sees a map point through the camera calibration the filter has now.
//
// A reference patch is cut from an image around the point's projection through the calibration
// in use then. With the camera's extrinsic and time shift in the state, the reference camera is
// the body pose of that image (moved along its motion by the change of the time shift since) times
// the state's extrinsic: a wrong extrinsic then shows in both views of a patch differently (the
// parallax between them), so the filter can observe it, instead of cancelling in the residual as
// it does when the reference is held fixed (README, "Calibration in the filter").
#pragma once

#include <Eigen/Core>

#include "livo/camera_projection.hpp"
#include "livo/filter_state.hpp"

namespace livo::vio {

/// The view a reference patch was cut in.
struct ReferenceView {
  Pose3 T_W_I = Pose3::Identity();                  // body pose at the patch's row (with the time shift then)
  Vec3 omega_I = Vec3::Zero();                      // body rate then (frame I)
  Vec3 vel_W = Vec3::Zero();                        // body velocity then
  Pose3 T_I_C = Pose3::Identity();                  // the extrinsic the patch was cut through
  double time_shift = 0.0;                          // the camera's time shift then (s)
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // level-0 pixel the stored patch is centred on

  /// The camera pose the patch was cut from.
  Pose3 cameraPose() const { return T_W_I * T_I_C; }
};

using Mat27 = Eigen::Matrix<double, 2, FilterState::kCalibrationDim>;

/// The level-0 pixel of p_W in the reference image through the calibration c (extrinsic and time
/// shift) and, if J is given, its derivative with respect to c's error state [δφ δρ δdt]
/// (right perturbation of R_I_C, additive t_I_C and dt): the reference body pose is T_W_I moved by
/// (c.dt - time_shift) along omega_I and vel_W; J_point: d pixel / d p_W. False if the point does
/// not project.
bool projectIntoReference(const CameraProjection& camera, const ReferenceView& view, const SensorCalibration& c,
                          const Vec3& p_W, Eigen::Vector2d* pixel, Mat27* J = nullptr,
                          Eigen::Matrix<double, 2, 3>* J_point = nullptr);

/// d pixel / d [δφ δρ] of a point at p_C (camera frame) for the extrinsic R_I_C (right
/// perturbation of R_I_C, t_I_C additive): J_proj [[p_C]x, -R_I_C^T].
Eigen::Matrix<double, 2, 6> pixelExtrinsicJacobian(const Eigen::Matrix<double, 2, 3>& J_proj, const Vec3& p_C,
                                                   const Mat3& R_I_C);

}  // namespace livo::vio
