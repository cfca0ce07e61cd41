// The LiDAR measurement of the ESIKF: point-to-plane residuals of a scan (undistorted, body frame)
// against the voxel map at each iterate, reduced to the information H^T R^-1 H and the vector
// H^T R^-1 z of the pose and the LiDAR's calibration (extrinsic and time shift, FilterState::kLidar).
// A point undistorted through the extrinsic T0 is q = T0^-1 p in the LiDAR frame; at an iterate x
// it is seen at x's extrinsic, from the body pose of the sweep's true end (the state's time plus
// the LiDAR's time shift dt, along the body rate ω and the velocity v):
//   w = R Exp(ω dt) (R_IL q + t_IL) + p + v dt,   r = n^T w + d.
// Planes are re-fitted only for points whose world image moved more than `research_distance` since
// their last neighbour search (usually once or twice a scan).
#pragma once

#include <limits>
#include <vector>

#include "livo/esikf_update.hpp"
#include "livo/lio/degeneracy.hpp"
#include "livo/lio/point_to_plane.hpp"
#include "livo/lio/voxel_map.hpp"
#include "livo/lio/voxel_planes.hpp"
#include "livo/worker_threads.hpp"

namespace livo::lio {

struct ScanToMapOptions {
  PlaneFitOptions plane;
  double point_noise_std = 0.02;        // m, standard deviation of one residual
  double residual_range_factor = 0.11;  // gate: |r| <= factor * sqrt(range) (FAST-LIO's test)
  double research_distance = 0.1;       // m, see above
  double robust_scale = 0.05;           // m, Cauchy kernel scale near the optimum (weight
                                        // 1 / (1 + (r/c)^2)); it damps residuals on planes
                                        // fitted across two surfaces (corners); 0: off
  double degeneracy_lever_arm = 1.0;    // m, L of the degeneracy test (degeneracy.hpp)
  double degeneracy_threshold = 0.003;  // eigenvalue of G below which a direction is degenerate
  bool remove_degenerate = true;        // drop the information of degenerate directions
  // The accuracy floor of one sweep's registration (1 sigma; rotation in rad, translation in m): the
  // map's own error (planes fitted to points that earlier, imperfect poses placed), shared by every
  // residual of the sweep, which no number of points averages away. The residuals' covariance is
  // point_noise_std^2 W^-1 + H_pose F H_pose^T (W: the robust weights, F: this floor), so a sweep
  // with thousands of residuals measures the pose no better than F (applyMeasurementFloor). 0: none.
  double registration_floor_rotation = 5e-5;  // 0.00286 deg
  double registration_floor_translation = 8e-4;
};

/// The matching options for a LiDAR whose range noise (1 sigma, along the beam) is `range_noise_std`,
/// from `base` (the options tuned at 1 cm): a plane's neighbours may lie 2 sigma from it (never thinner
/// than base's), and k grows from base's (5) at 1 cm to base + 3 at 3 cm and more, so the fitted plane
/// averages the noise. One residual's standard deviation combines the model error of the accepted
/// planes (curvature, discretisation: sqrt(0.02^2 - 1.2 * 0.01^2) = 1.7 cm at the 1 cm tuning, scaled
/// with the plane thickness the options accept, since a thicker gate lets more curved neighbourhoods
/// pass) with the noise of the point and of a plane fitted to k noisy neighbours:
/// sqrt((thickness / base thickness)^2 floor^2 + (1 + 1/k) sigma^2), never below base's (3.1 cm at
/// sigma = 2 cm, 4.6 cm at 3 cm). At 1 cm and below the result is `base`.
ScanToMapOptions matchingForRangeNoise(double range_noise_std, const ScanToMapOptions& base = {});

class ScanToMap {
 public:
  /// `map` must outlive this object and stay unchanged while it is used; `body_points` were
  /// undistorted through the LiDAR calibration `undistorted_with` (its extrinsic and time shift) and
  /// `body_rate` is the bias-corrected angular rate at the sweep end (frame I). With `threads`, the neighbour searches
  /// of an iterate are shared among them; the result is the same bit for bit. `planes` (may be null) answer first where
  /// they have a plane; the map's k nearest points elsewhere.
  ScanToMap(const VoxelMap& map, const VoxelPlanes* planes, const std::vector<Vec3>& body_points,
            const ScanToMapOptions& options, WorkerThreads* threads = nullptr,
            const SensorCalibration& undistorted_with = {}, const Vec3& body_rate = Vec3::Zero());

  /// Measurement for iteratedUpdate.
  bool evaluate(const FilterState& x, int iteration, MeasurementInformation* info);

  /// Residuals accepted at the last evaluate().
  int numResiduals() const { return last_count_; }
  /// Points that have a fitted plane (after the last evaluate()).
  int numMatched() const;
  /// Degeneracy of the last evaluate().
  const DegeneracyReport& degeneracy() const { return degeneracy_; }
  /// Smallest eigenvalue of H^T R^-1 H at the last evaluate(), before any removal.
  double minInformationEigenvalue() const { return min_information_eigenvalue_; }

 private:
  struct Match {
    Plane plane;
    Vec3 searched_at = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
    bool has_plane = false;
    bool observes_normal = false;  // the plane stays one with any of its neighbours left out
  };
  struct Row {
    Eigen::Matrix<double, 1, kMeasuredDim> h;
    double r;
    bool observes_normal;  // counts in the degeneracy test; only these are used in a degenerate sweep
  };
  // The stages of evaluate(), in order.
  /// The points' images at the LiDAR pose (R_WL, t_WL) into world_; returns those that moved enough
  /// since their last search (all at the first iteration) to search their neighbours anew.
  std::vector<uint32_t> placePoints(const Mat3& R_WL, const Vec3& t_WL, int iteration);
  /// The neighbour searches and plane fits of those points (on the threads, if any) into matches_.
  void fitPlanes(const std::vector<uint32_t>& to_search);
  /// The gated point-to-plane residuals, in the points' order.
  std::vector<Row> residualRows(const FilterState& x, const Pose3& sweep_end) const;
  /// The Cauchy kernel's squared scale for these residuals (0: no kernel).
  double robustScale2(const std::vector<Row>& rows) const;
  /// G of the degeneracy test (degeneracy.hpp) from the rows that observe their plane's normal.
  Mat6 degeneracyGeometry(const std::vector<Row>& rows) const;
  /// H^T R^-1 H and H^T R^-1 z of the rows, robustly weighted (only the normal-observing rows in a
  /// degenerate sweep).
  void information(const std::vector<Row>& rows, double c2, bool degenerate, Mat13* S, Vec13* g) const;

  const VoxelMap& map_;
  const VoxelPlanes* planes_;
  std::vector<Vec3> points_;  // the points in the LiDAR frame (q above)
  Vec3 body_rate_;
  double undistorted_dt_;  // the time shift the points were undistorted with
  ScanToMapOptions options_;
  WorkerThreads* threads_;
  std::vector<Match> matches_;
  std::vector<double> gate_;     // per point: max |r|
  std::vector<Vec3> world_;      // per point: its image at the current iterate
  Mat13 floor_ = Mat13::Zero();  // the registration floor over the measured states
  DegeneracyReport degeneracy_;
  double min_information_eigenvalue_ = 0.0;
  int last_count_ = 0;
};

}  // namespace livo::lio
