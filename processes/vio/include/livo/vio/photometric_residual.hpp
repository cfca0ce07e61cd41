// The photometric residual of one map point (paper eq. 10) and its Jacobian with respect to the body
// pose and the camera's calibration in the filter state (extrinsic and time shift).
//
// For a tracked point with reference patch Q and the current image I sampled on the 8x8 grid around
// the point's projection u(x):
//   r = I(u(x) + d) - (a Q(s(x) + A d) + b),
// with the gain a and offset b fitted per patch by least squares (a kept within bounds around the
// exposure ratio; offset only if affine brightness is off), A the warp into the reference view and
// s(x) where the reference image sees the point through the state's calibration, relative to where
// the stored patch was cut (reference_view.hpp). Both projections depend on the calibration: a
// rotation of the camera against the body moves them alike and cancels, what is left is the
// parallax between the two views, which the filter observes; a reference patch held fixed would
// cancel it entirely and leave a bias the filter cannot see (README, "Calibration in the filter").
// The fit is a projection Π; by Kaufman's variable-projection approximation
//   dr/dx = (1 - Π) [∇I du/dx - a ∇Q ds/dx],
// ∇I by central differences of the current image at the level and du/dx and ds/dx the pixels'
// Jacobians with respect to [δθ δp δφ δρ δdt] at the patch centre. The reference's gradient is
// taken as the current image's through the warp, a ∇Q = A^-T ∇I (exact once aligned): a rotation
// of both views alike then cancels exactly, as it does in the images, and the information left is
// the parallax between them (the stored patch's own gradient, 8-bit and interpolated, differs
// from the image's by noise that would pass for information on the calibration).
#pragma once

#include <array>

#include <Eigen/Core>

#include "livo/camera_projection.hpp"
#include "livo/esikf_update.hpp"
#include "livo/filter_state.hpp"
#include "livo/vio/image_pyramid.hpp"
#include "livo/vio/patch.hpp"
#include "livo/vio/reference_view.hpp"
#include "livo/vio/rolling_shutter.hpp"
#include "livo/vio/vio_options.hpp"

namespace livo::vio {

/// A map point tracked in the current image: its reference patch warped into this view.
struct TrackedPatch {
  int point = -1;        // index into the map
  int observation = -1;  // the reference observation
  Vec3 p_W = Vec3::Zero();
  float gain0 = 1.0f;                   // expected gain: exposure ratio current / reference, 1 if unknown
  float gradient = 0.0f;                // texture strength of the reference
  ReferenceView view;                   // the view the reference was cut in
  Mat6 reference_cov_W = Mat6::Zero();  // its pose covariance [rotation (world frame), position]
  // the reference warped into this view at the level-0 shift `shift0` (the reference's projection
  // through the prior's calibration, relative to the stored patch's centre), per level row-major
  // 8x8, and the derivatives of each sample with respect to the shift (level pixels)
  Eigen::Vector2d shift0 = Eigen::Vector2d::Zero();
  Eigen::Matrix2d warp = Eigen::Matrix2d::Identity();  // A: reference offsets per current offset
  std::array<float, kPatchArea * kMaxLevels> reference{};
  std::array<float, kPatchArea * kMaxLevels> reference_dx{};
  std::array<float, kPatchArea * kMaxLevels> reference_dy{};
  // filled by the update (level 0, at the posterior)
  bool active = false;
  float ncc = 0.0f;
  float rms = 0.0f;  // residual RMS after the brightness fit, grey levels

  /// The camera centre the reference was captured from.
  Vec3 referenceCentre() const { return view.cameraPose().translation(); }
};

using Mat26 = Eigen::Matrix<double, 2, 6>;
using Mat4x13 = Eigen::Matrix<double, 4, kMeasuredDim>;

/// d pixel / d [δrot δpos] for the body pose (R_W_I, right perturbation; p_W_I) of a world point
/// whose body-frame coordinates are p_I, given d pixel / d p_C (J_proj).
Mat26 pixelPoseJacobian(const Eigen::Matrix<double, 2, 3>& J_proj, const Mat3& R_W_I, const Pose3& T_I_C,
                        const Vec3& p_I);

/// d pixel / d [δrot δpos] of the stamp's body pose for a point seen through a rolling shutter
/// at row time s.dt (the row's time held fixed: its change with the pose is second order).
Mat26 pixelPoseJacobian(const ShutterProjection& s, const RollingShutter& shutter, const Pose3& T_I_C);

/// d pixel / d [δrot δpos δφ δρ δdt] of a point seen through a rolling shutter from the state x
/// at its true time (the stamp plus the camera's time shift: `advanced(x, ω, x.camera.dt)`), for
/// the error state of x at the stamp.
Eigen::Matrix<double, 2, kMeasuredDim> currentPixelJacobian(const ShutterProjection& s, const RollingShutter& shutter,
                                                            const FilterState& x);

struct PatchResidual {
  Eigen::Matrix<double, kPatchArea, 1> r;  // residuals, grey levels
  // d r / d [current pixel; reference pixel] (level pixels), the brightness fit projected out
  Eigen::Matrix<double, kPatchArea, 4> G;
  Mat4x13 B;                       // d [current pixel; reference pixel] (level) / d [δθ δp δφ δρ δdt]
  Eigen::Matrix<double, 4, 3> Bp;  // d [current pixel; reference pixel] (level) / d p_W (the map point)
  Mat26 Bref;                      // d reference pixel (level) / d [δθ δp] of the reference's body pose
  double baseline = 0.0;           // m between the two camera centres
  Eigen::Vector2d pixel;           // level-0 projection
  double gain = 1.0, offset = 0.0, ncc = 0.0;

  /// d r / d [δθ δp δφ δρ δdt] (64 x 13).
  Eigen::Matrix<double, kPatchArea, kMeasuredDim> jacobian() const { return G * B; }
};

/// Evaluates the patch at level `level` for the state x (at the image stamp, with the camera's
/// calibration; each point seen at its row's time under a rolling shutter whose omega_I is the
/// body rate); false if the point does not project with its window inside that level, or the
/// reference's re-centred sample leaves its stored patch.
bool evaluatePatch(const ImagePyramid& pyramid, int level, const CameraProjection& camera, const FilterState& x,
                   const TrackedPatch& patch, const PhotometricOptions& options, PatchResidual* out,
                   const RollingShutter& shutter = RollingShutter());

/// Adds the patch's Huber-weighted information (H^T R^-1 H, H^T R^-1 z with R = noise_std^2) to
/// `info` (calibration block FilterState::kCamera); returns its Huber cost (sum over pixels, grey
/// levels^2). The map point is a LiDAR return, known to options.point_std per axis: it is a nuisance
/// of the patch, eliminated by its Schur complement against that prior (a point error moves both
/// views of the patch, much as a calibration error does, and would otherwise be taken for one).
double accumulate(const PatchResidual& e, const PhotometricOptions& options, MeasurementInformation* info);

/// Huber cost of the residuals alone.
double huberCost(const PatchResidual& e, double threshold);

}  // namespace livo::vio
