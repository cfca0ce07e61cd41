// The direct photometric VIO core (no LCM): the point-patch map fed with registered LiDAR
// scans, and per image at a filter prior the coarse-to-fine iterated ESIKF update followed by map
// maintenance (new points from the recent scans on a gradient-selected grid, new patches when
// the view or the photometric error changed enough, pruning to the bounds).
//
//   VioEstimator vio(options, camera_rig);
//   vio.addScan(scan_utime, world_points);                 // REGISTERED_SCAN
//   ImageResult r = vio.processImage(grey, prior, P);      // at a STATE_PRIOR
//   if (r.valid) { use r.state, r.covariance }
//
// Camera pose = W_T_I * T_I_C (the rig's extrinsic). The scans are in the world frame (points
// undistorted by the LIO), so a scan from before or after the image is equally valid as a source
// of points: only its field of view matters, and projecting it selects the points in the camera's.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "livo/camera_projection.hpp"
#include "livo/filter_state.hpp"
#include "livo/vio/camera_rotation_calibration.hpp"
#include "livo/vio/direct_update.hpp"
#include "livo/vio/grey_image.hpp"
#include "livo/vio/image_pyramid.hpp"
#include "livo/vio/point_patch_map.hpp"
#include "livo/vio/point_selection.hpp"
#include "livo/vio/rolling_shutter.hpp"
#include "livo/vio/vio_options.hpp"

namespace livo::vio {

/// One point per map voxel of a registered scan (world frame; non-finite points skipped): the
/// voxel's first point, moved onto the plane of the voxel's points when they are flat
/// (MapOptions::plane_snap_*).
std::vector<Vec3> voxelPoints(const float* x, const float* y, const float* z, size_t n, const MapOptions& options);

struct ImageResult {
  bool valid = false;                // an update to adopt
  std::string why;                   // why not
  FilterState state;                 // posterior (the prior if not valid)
  Mat18 covariance = Mat18::Zero();
  int iterations = 0;
  int num_measurements = 0;          // scalar photometric residuals of the last step
  int patches = 0;                   // patches of the last step
  double mahalanobis = 0.0;
  double cost_prior = 0.0, cost_post = 0.0;
  SelectionStats selection;
  int new_points = 0;                // added to the map from the recent scans
  int candidates = 0;                //   recent scan points in free cells of the image
  int candidates_hidden = 0;         //   ... refused as occluded or on a depth edge
  int candidates_weak = 0;           //   ... cells whose best candidate had too little texture
  int new_patches = 0;               // observations added to tracked points
  size_t map_points = 0;             // after maintenance
  bool camera_rotation_changed = false;  // the rotation calibration was adopted before this image's
                                         // update (the point-patch map started afresh)
};

class VioEstimator {
 public:
  VioEstimator(const VioOptions& options, const CameraRig& camera);

  /// A registered scan (world frame, `n` points); keeps the newest `recent_scans`, one point per
  /// map voxel (voxelPoints).
  void addScan(int64_t utime, const float* x, const float* y, const float* z, size_t n);
  void addScan(int64_t utime, const std::vector<Vec3>& points);

  /// A gyro sample (IMU clock, body frame): the body rate a rolling shutter's rows are placed with
  /// and the time offset is estimated with (kept only if needsGyro()).
  void addGyro(int64_t utime, const Vec3& angular_velocity);
  /// A rolling shutter or the online time-offset calibration use the body rate.
  bool needsGyro() const { return shutter_.active() || options_.calibration.time_offset_std > 0.0; }
  /// Update at an image whose time the prior refers to (image.utime already on the IMU clock).
  /// `camera_free`: lio's LiDAR-inertial-only state at the image (rotation calibration against
  /// camera_free; null if there is none for this image).
  ImageResult processImage(const GreyImage& image, const FilterState& prior, const Mat18& P,
                           const FilterState* camera_free = nullptr);

  /// A loop correction: moves the map and the recent scans by T_corrected_odom.
  void applyCorrection(const Pose3& T_corrected_odom);
  void reset();

  const PointPatchMap& map() const { return map_; }
  const VioOptions& options() const { return options_; }
  const CameraProjection& camera() const { return camera_; }
  /// The rotation calibration from image pairs (null unless options.rotation_calibration.enabled).
  const CameraRotationCalibration* rotationCalibration() const {
    return rotation_calibration_ ? &*rotation_calibration_ : nullptr;
  }
  /// The camera extrinsic in use (the rig's, corrected online if calibration is on).
  const Pose3& cameraExtrinsic() const { return T_I_C_; }
  const ImagePyramid& pyramid() const { return pyramid_; }  // of the last image
  size_t recentScanPoints() const;
  /// The shutter of an image at state x: the rig's line time and the body rate: the mean gyro
  /// sample within kGyroWindow of the image less the state's gyro bias; without samples the
  /// rotation since the last image's posterior (zero for the first image, after a gap or a correction).
  RollingShutter shutterAt(int64_t utime, const FilterState& x) const;
  /// That body rate (whether or not the shutter rolls).
  Vec3 bodyRateAt(int64_t utime, const FilterState& x) const;
  /// The estimated image time offset against the LIO's clock (s; 0 unless estimated).
  double timeOffset() const { return time_offset_; }
  /// Covariance of the next correction c = [φ ρ δt] (photometric_residual.hpp).
  const CalibrationMatrix& calibrationCovariance() const { return calibration_cov_; }

 private:
  struct Scan {
    int64_t utime = 0;
    std::vector<Vec3> points;
  };
  void fillDepth(const Pose3& T_W_C);
  void maintain(const GreyImage& image, const FilterState& x, const RollingShutter& shutter, bool refresh, const std::vector<TrackedPatch>& tracked,
                ImageResult* result);
  bool makeObservation(const Eigen::Vector2d& pixel, const GreyImage& image, const Pose3& T_W_C, const Mat6& pose_cov_W,
                       PatchObservation* obs) const;

  VioOptions options_;
  CameraProjection camera_;
  Pose3 T_I_C_;
  PointPatchMap map_;
  std::deque<Scan> scans_;   // newest last
  ImagePyramid pyramid_;
  DepthGrid depth_;
  RollingShutter shutter_;       // line time of the rig; no motion
  int64_t last_utime_ = -1;      // the last image's time and posterior rotation (body rate)
  Mat3 last_rot_ = Mat3::Identity();
  std::deque<std::pair<int64_t, Vec3>> gyro_;  // recent gyro samples, oldest first
  std::optional<CameraRotationCalibration> rotation_calibration_;
  Vec3 adopted_rotation_ = Vec3::Zero();  // the correction T_I_C_ has (rotation_calibration_)
  bool rotation_adopted_ = false;
  CalibrationMatrix calibration_cov_ = CalibrationMatrix::Zero();  // of the corrections folded into
                                                                    // T_I_C_ and time_offset_
  double time_offset_ = 0.0;     // s: an image stamped t was taken at t + time_offset_ (LIO clock)
};

}  // namespace livo::vio
