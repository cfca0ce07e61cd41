// The photometric residual of one map point (paper eq. 10) and its Jacobian wrt the body pose.
//
// For a tracked point with reference patch Q (warped into the current view) and the current
// image I sampled on the 8x8 grid around the point's projection u(x):
//   r = I(u(x) + d) - (a Q(d) + b),
// with the gain a and offset b fitted per patch by least squares (a kept within bounds around
// the exposure ratio; offset only if affine brightness is off). Since the fit is a projection
// that does not depend on the pose, r = (1 - Pi) I(u(x) + d) and, exactly,
//   dr/dx = (1 - Pi) grad I · du/dx,
// grad I by central differences of the current image at the level, du/dx (2x6) the pixel's
// Jacobian wrt the right perturbation of W_R_I and W_p_I, evaluated at the patch centre.
#pragma once

#include <array>

#include <Eigen/Core>

#include "livo/camera_projection.hpp"
#include "livo/esikf_update.hpp"
#include "livo/filter_state.hpp"
#include "livo/vio/image_pyramid.hpp"
#include "livo/vio/patch.hpp"
#include "livo/vio/rolling_shutter.hpp"
#include "livo/vio/vio_options.hpp"

namespace livo::vio {

/// A map point tracked in the current image: its reference patch warped into this view.
struct TrackedPatch {
  int point = -1;             // index into the map
  int observation = -1;       // the reference observation
  Vec3 p_W = Vec3::Zero();
  float gain0 = 1.0f;         // expected gain: exposure ratio current / reference, 1 if unknown
  float gradient = 0.0f;      // texture strength of the reference
  Vec3 reference_centre = Vec3::Zero();  // W: the camera centre the reference was captured from
  Mat6 reference_cov_W = Mat6::Zero();   // its pose covariance [rotation (world frame), position]
  std::array<float, kPatchArea * kMaxLevels> reference{};  // per level, row-major 8x8
  // filled by the update (level 0, at the posterior)
  bool active = false;
  float ncc = 0.0f;
  float rms = 0.0f;           // residual RMS after the brightness fit, grey levels
};

using Mat26 = Eigen::Matrix<double, 2, 6>;

/// d pixel / d [δrot δpos] for the body pose (R_W_I, right perturbation; p_W_I) of a world point
/// whose body-frame coordinates are p_I, given d pixel / d p_C (J_proj).
Mat26 pixelPoseJacobian(const Eigen::Matrix<double, 2, 3>& J_proj, const Mat3& R_W_I, const Pose3& T_I_C, const Vec3& p_I);

struct PatchResidual {
  Eigen::Matrix<double, kPatchArea, 1> r;  // residuals, grey levels
  Eigen::Matrix<double, kPatchArea, 2> G;  // d r / d pixel (level pixels), brightness fit projected out
  Mat26 B;                                 // d pixel (level) / d pose
  Eigen::Matrix<double, 2, 6> Bc;          // d pixel (level) / d [φ ρ], the camera extrinsic's
                                           // correction T_I_C (Exp(φ), ρ) (CalibrationInformation)
  Eigen::Vector2d pixel;                   // level-0 projection
  double gain = 1.0, offset = 0.0, ncc = 0.0;

  /// d r / d [δrot δpos] (64 x 6).
  Eigen::Matrix<double, kPatchArea, 6> jacobian() const { return G * B; }
};

/// d pixel / d [δrot δpos] of the stamp's body pose for a point seen through a rolling shutter
/// at row time s.dt (the row's time held fixed: its change with the pose is second order).
Mat26 pixelPoseJacobian(const ShutterProjection& s, const RollingShutter& shutter, const Pose3& T_I_C);

/// Evaluates the patch at level `level` for the state x (at the image stamp; each point seen at its
/// row's time under a rolling shutter); false if the point does not project with its window
/// inside that level.
bool evaluatePatch(const ImagePyramid& pyramid, int level, const CameraProjection& camera, const Pose3& T_I_C,
                   const FilterState& x, const TrackedPatch& patch, const PhotometricOptions& options,
                   PatchResidual* out, const RollingShutter& shutter = RollingShutter());

/// Adds the patch's Huber-weighted information (H^T R^-1 H, H^T R^-1 z with R = noise_std^2) to
/// `info`; returns its Huber cost (sum over pixels, grey levels^2).
double accumulate(const PatchResidual& e, const PhotometricOptions& options, PoseInformation* info);

/// The camera's calibration against the LiDAR-registered body, corrected online as a nuisance of
/// the update: c = [φ ρ δt], the extrinsic T_I_C (Exp(φ), ρ) (camera frame) and the image taken at
/// its stamp + δt (the body then at R Exp(ω δt), p + v δt).
constexpr int kCalibrationDim = 7;
using CalibrationVector = Eigen::Matrix<double, kCalibrationDim, 1>;
using CalibrationMatrix = Eigen::Matrix<double, kCalibrationDim, kCalibrationDim>;

/// The information of the correction c beside the pose's: S_xc = H_x^T R^-1 H_c,
/// S_cc = H_c^T R^-1 H_c, g_c = H_c^T R^-1 z.
struct CalibrationInformation {
  Eigen::Matrix<double, 6, kCalibrationDim> S_xc = Eigen::Matrix<double, 6, kCalibrationDim>::Zero();
  CalibrationMatrix S_cc = CalibrationMatrix::Zero();
  CalibrationVector g_c = CalibrationVector::Zero();
};

/// accumulate() that also adds the calibration terms of the same Huber-weighted residuals;
/// `motion` = [ω_I; v_W] at the image gives the δt column, d pixel / d δt = B motion.
double accumulate(const PatchResidual& e, const PhotometricOptions& options, PoseInformation* info,
                  const Vec6& motion, CalibrationInformation* calibration_info);

/// Huber cost of the residuals alone.
double huberCost(const PatchResidual& e, double threshold);

}  // namespace livo::vio
