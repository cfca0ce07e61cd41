// The camera's rotation against the body the LIO estimates, from the geometry of image pairs.
//
// The rig's T_I_C rotation is known to a few tenths of a degree, and so is the LiDAR's; the LIO's
// body is registered through the LiDAR. That relative rotation ε biases every photometric pose
// measurement by about ε × b (b: the camera's travel since a reference patch was cut), and the
// photometric residuals cannot estimate it, their references having been cut through the same
// rotation (README, "Limits"). The geometry of two images can:
//
//   corners tracked with KLT from image 0 to image 1, the LIO's poses T_W_I0, T_W_I1 and
//   T_I_C(φ) = (R_I_C,rig Exp(φ), t_I_C) give C0_T_C1 = (R(φ), t(φ)), and every track's rays
//   satisfy r0ᵀ [t]× R r1 = 0.
//
// φ is the rotation correction that makes the tracks epipolar (Sampson error, Cauchy loss) over
// a window of pairs. A rotation about any camera axis moves the epipole or the rotation the
// tracks show, so it is observed even while the body turns about one axis only (a ground
// vehicle's yaw). The residuals of a pair share the LIO's relative-pose error, so φ's covariance
// is the sandwich estimate with one cluster per pair, not the inverse Hessian.
//
// Under a rolling shutter each row is seen from its own pose: the ray is turned back to the
// stamp's camera with the body rate, and the row's offset along the velocity during the readout
// goes into that track's baseline (t_i = t + R_C0_W (v1 dt1_i − v0 dt0_i)). The essential-matrix
// RANSAC (OpenCV, deterministic) drops tracks on moving objects before the fit.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "livo/camera_projection.hpp"
#include "livo/vio/rolling_shutter.hpp"
#include "livo/vio/vio_options.hpp"

namespace livo::vio {

/// Two images' views of the same corners (normalised image points (x/z, y/z, 1) in the camera
/// frame at each image's stamp) and the LIO's body poses at the two stamps.
struct TrackPair {
  Pose3 T_W_I0 = Pose3::Identity(), T_W_I1 = Pose3::Identity();
  std::vector<Vec3> x0, x1;
  /// Per track (empty: global shutter), world frame: how much farther apart the two rows' camera
  /// centres are than the stamps' (v1 dt1 − v0 dt0, dt the row time).
  std::vector<Vec3> readout_shift_W;
};

struct RotationEstimate {
  Vec3 correction = Vec3::Zero();         // φ, rad: R_I_C = R_I_C,rig Exp(φ)
  Mat3 covariance = Mat3::Identity();     // rad², cluster-robust (one cluster per pair)
  int pairs = 0;
  int residuals = 0;
  double rms_px = 0.0;                    // Sampson error at φ, inliers of the Cauchy loss
  /// 1-sigma of the worst-known axis, deg.
  double maxStdDeg() const;
};

/// Sampson error (normalised image units) of the points x0, x1 (z = 1) under the essential matrix
/// E = [t]× R of the relative pose C0_T_C1 = (R, t).
double sampsonError(const Vec3& x0, const Vec3& x1, const Mat3& E);

/// φ minimising the Cauchy-weighted Sampson errors of all pairs (Gauss-Newton from `initial`);
/// `cauchy` in normalised image units, `focal` (px) only for rms_px.
RotationEstimate solveCameraRotation(const std::deque<TrackPair>& pairs, const Pose3& T_I_C_rig, const Vec3& initial,
                                     double cauchy, double focal);

/// The pairs' estimate fused with the rig's own rotation, taken as a prior of `rig_std` rad per
/// axis about the rig's (the stated 1-sigma of the camera's rotation against the LiDAR,
/// update.calibration_rotation_std_deg): φ = (P0⁻¹ + P⁻¹)⁻¹ P⁻¹ φ_pairs. What a later run over the
/// same rig should use: an estimate much surer than the rig is taken nearly whole, a vague one
/// barely moves it. rig_std 0: the estimate whole.
struct FusedCameraRotation {
  Vec3 correction = Vec3::Zero();      // rad: R_I_C = R_I_C,rig Exp(correction)
  Mat3 covariance = Mat3::Identity();  // rad²
  Pose3 T_I_C = Pose3::Identity();     // the rig's translation, the fused rotation
};
FusedCameraRotation fuseWithRig(const Pose3& T_I_C_rig, const RotationEstimate& estimate, double rig_std);

/// A project-config overlay (livo::Config::load with overlays, livo-config merge) that sets
/// rig.camera.T_I_C to `fused` (a 16-number row-major matrix, so it replaces the rig's entry
/// whatever form that has), with comments giving the estimate, the fusion and the quaternion.
std::string cameraRotationOverlay(const FusedCameraRotation& fused, const RotationEstimate& estimate, int pairs_closed,
                                  double rig_std);

class CameraRotationCalibration {
 public:
  CameraRotationCalibration(const RotationCalibrationOptions& options, const CameraProjection& camera,
                            const Pose3& T_I_C_rig);

  /// An image (8-bit grey) at the LIO's body pose T_W_I and velocity v_W at its stamp, with its
  /// rolling shutter. True if the estimate was solved again (every tenth pair it closes).
  bool addImage(const cv::Mat& grey, int64_t utime, const Pose3& T_W_I, const Vec3& v_W, const RollingShutter& shutter);
  /// A loop correction T_corrected_odom: the open pair's first pose moves with the map.
  void applyCorrection(const Pose3& T_corrected_odom);
  void reset();
  /// Drops the tracks and the open pair (an image without a body pose); the estimate stays.
  void restartTracks();

  const RotationEstimate& estimate() const { return estimate_; }
  /// Enough pairs and every axis known to options.apply_std_deg.
  bool converged() const;
  /// Solved on at least options.min_pairs pairs (converged or not).
  bool hasEstimate() const { return estimate_.pairs >= options_.min_pairs; }
  /// T_I_C with the estimated rotation.
  Pose3 calibratedExtrinsic() const;
  size_t tracks() const { return key_px_.size(); }
  /// Image pairs closed since the start (the estimate uses the newest window_pairs).
  int pairsClosed() const { return pairs_closed_; }

 private:
  Vec3 rayAtStamp(const cv::Point2f& px, const RollingShutter& shutter) const;
  void startPair(const cv::Mat& grey, int64_t utime, const Pose3& T_W_I, const Vec3& v_W, const RollingShutter& shutter);

  RotationCalibrationOptions options_;
  CameraProjection camera_;
  Pose3 T_I_C_rig_;
  // the open pair: its first image's time and pose, and per track the corner there (ray) and now
  int64_t key_utime_ = -1;
  Pose3 key_T_W_I_ = Pose3::Identity();
  Vec3 key_v_W_ = Vec3::Zero();
  std::vector<Vec3> key_ray_;
  std::vector<double> key_dt_;  // row times
  std::vector<cv::Point2f> key_px_, cur_px_;
  std::vector<cv::Mat> prev_pyramid_;
  std::deque<TrackPair> pairs_;
  int pairs_since_solve_ = 0;
  int pairs_closed_ = 0;
  RotationEstimate estimate_;
};

}  // namespace livo::vio
