// The direct photometric VIO core (no LCM): the point-patch map fed with registered LiDAR
// scans, and per image at a filter prior the coarse-to-fine iterated ESIKF update followed by map
// maintenance (new points from the recent scans on a gradient-selected grid, new patches when
// the view or the photometric error changed enough, pruning to the bounds).
//
//   VioEstimator vio(options, camera_rig);
//   vio.addScan(scan_utime, world_points);                 // REGISTERED_SCAN
//   ImageResult r = vio.processImage(grey, prior, P, body_rate);  // at a STATE_PRIOR
//   if (r.valid) { use r.state, r.covariance }
//
// Camera pose = W_T_I * T_I_C, the extrinsic and the image's time shift being the filter's
// (FilterState::camera: estimated by the update where the rig states an uncertainty). The scans
// are in the world frame (points
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
/// (MapOptions::plane_snap_*). With `normals`: per returned point the unit normal of that plane
/// where the voxel's points form one (MapOptions::normal_*), zero elsewhere.
std::vector<Vec3> voxelPoints(const float* x, const float* y, const float* z, size_t n, const MapOptions& options,
                              std::vector<Vec3>* normals = nullptr);

struct ImageResult {
  bool valid = false;  // an update to adopt
  std::string why;     // why not
  FilterState state;   // posterior (the prior if not valid)
  StateCovariance covariance = StateCovariance::Zero();
  int iterations = 0;
  int num_measurements = 0;     // scalar photometric residuals of the last step
  int patches = 0;              // patches of the last step
  ConsistencyTest consistency;  // of the image's measurement against the prior
  double cost_prior = 0.0, cost_post = 0.0;
  SelectionStats selection;
  int new_points = 0;         // added to the map from the recent scans
  int candidates = 0;         //   recent scan points in free cells of the image
  int candidates_hidden = 0;  //   ... refused as occluded or on a depth edge
  int candidates_weak = 0;    //   ... cells whose best candidate had too little texture
  int new_patches = 0;        // observations added to tracked points
  size_t map_points = 0;      // after maintenance
};

class VioEstimator {
 public:
  VioEstimator(const VioOptions& options, const CameraRig& camera);

  /// A registered scan (world frame, `n` points); keeps the newest `recent_scans`, one point per
  /// map voxel (voxelPoints).
  void addScan(int64_t utime, const float* x, const float* y, const float* z, size_t n);
  void addScan(int64_t utime, const std::vector<Vec3>& points);

  /// Update at an image whose time the prior refers to (image.utime already on the IMU clock);
  /// `body_rate`: the bias-corrected angular rate there (filter_state_t.angular_velocity), for the
  /// rolling shutter's rows and the camera's time shift.
  ImageResult processImage(const GreyImage& image, const FilterState& prior, const StateCovariance& P,
                           const Vec3& body_rate);

  /// A loop correction: moves the map and the recent scans by T_corrected_odom.
  void applyCorrection(const Pose3& T_corrected_odom);
  void reset();

  const PointPatchMap& map() const { return map_; }
  const VioOptions& options() const { return options_; }
  const CameraProjection& camera() const { return camera_; }
  const ImagePyramid& pyramid() const { return pyramid_; }  // of the last image
  size_t recentScanPoints() const;

 private:
  struct Scan {
    int64_t utime = 0;
    std::vector<Vec3> points;
    std::vector<Vec3> normals;  // per point, zero where its voxel is not a plane
  };
  struct ImageCamera;        // the camera when the image was taken (vio_estimator.cpp)
  struct NewPointCandidate;  // of a free cell
  void fillDepth(const Pose3& T_W_C);
  /// Map maintenance after an image; `x`: the posterior at the image stamp.
  void maintain(const GreyImage& image, const FilterState& x, const RollingShutter& shutter, bool refresh,
                const std::vector<TrackedPatch>& tracked, ImageResult* result);
  /// The tracked points seen now (their cells marked `occupied`); with `refresh`, a new patch where
  /// the view or the photometric error changed enough. Returns the patches added.
  int refreshTracked(const GreyImage& image, const ImageCamera& cam, const Mat6& pose_cov_W, bool refresh,
                     const std::vector<TrackedPatch>& tracked, const CellGrid& grid, std::vector<char>* occupied);
  /// Per free cell the best-textured recent LiDAR point (newest scan first); counts the candidates
  /// and the hidden ones in `result`.
  std::vector<NewPointCandidate> newPointCandidates(const ImageCamera& cam, const CellGrid& grid,
                                                    const std::vector<char>& occupied, ImageResult* result) const;
  /// The candidates with texture enough as new map points (at most MaintenanceOptions::max_new_points).
  void addNewPoints(const GreyImage& image, const ImageCamera& cam, const Mat6& pose_cov_W,
                    const std::vector<NewPointCandidate>& best, ImageResult* result);
  bool makeObservation(const Eigen::Vector2d& pixel, const GreyImage& image, const ReferenceView& view,
                       const Mat6& pose_cov_W, PatchObservation* obs) const;

  VioOptions options_;
  CameraProjection camera_;
  PointPatchMap map_;
  std::deque<Scan> scans_;  // newest last
  ImagePyramid pyramid_;
  DepthGrid depth_;
  RollingShutter shutter_;  // line time of the rig; no motion
};

}  // namespace livo::vio
