// Ground-map thickness: how thick the ground becomes in the map an estimator builds from its
// registered scans. A drifting height or pitch puts the same patch of ground at different heights
// in different sweeps; ground (planar) constraints are meant to prevent exactly that.
//
// Per point p_w of a scan (world frame, where the estimator registered it): its body-frame position
// b = T_est^-1 p_w (T_est: the estimator's pose of that scan) and its true world position
// q = T_gt(t) b (the ground truth interpolated at the scan's stamp). Points are binned by q's x, y
// into square cells; a cell's ground points are those whose true height q.z lies within the band
// [f, f + band] above f, the 5th percentile of the cell's true heights: the lowest layer, the ground
// or the cover on it, found from the truth so that the estimate's errors cannot choose the points
// they are judged on. The percentile rather than the lowest height, so that a few stray low returns
// do not set the floor. A cell counts with at least 10 ground points from at least 2 scans; its
// thickness is the standard deviation of the ground points' estimated heights p_w.z, its truth floor
// that of their true heights q.z (the real relief and the range noise: what a perfect estimator
// would show). Cells are per odometry epoch: a reset starts an unrelated world frame.
#pragma once

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "livo/evaluate/error_statistics.hpp"
#include "livo/so3.hpp"
#include "livo/trajectory_io.hpp"

namespace livo::evaluate {

/// One registered scan: the estimator's body pose at `utime` and the world-frame points it
/// registered (structure of arrays, as livo.point_cloud_t holds them; `size` points each).
struct GroundScan {
  int64_t utime = 0;
  Pose3 T_W_I = Pose3::Identity();
  int32_t epoch = 0;
  const float* x = nullptr;
  const float* y = nullptr;
  const float* z = nullptr;
  size_t size = 0;
};

using GroundScanVisitor = std::function<void(const GroundScan&)>;
/// Calls the visitor for every scan, in the same order on every call: the thickness reads the
/// scans twice and keeps none of them.
using GroundScanSource = std::function<void(const GroundScanVisitor&)>;

struct GroundMapOptions {
  double cell_m = 0.5;            // side of the square cells (true x, y)
  double band_m = 0.2;            // height of the ground layer above a cell's 5th percentile
  double max_dt = 0.05;           // s: the ground-truth poses on either side of a scan's stamp at most this far
  Vec3 gt_offset = Vec3::Zero();  // body frame: the point the ground truth tracks (--gt-offset)

  /// Throws std::invalid_argument naming the offending option.
  void validate() const;
};

struct GroundMapThickness {
  std::string source;  // what was read (the command's --ground-map)
  double cell_m = 0.0;
  double band_m = 0.0;
  std::vector<double> thickness_m;  // per counted cell: std of the ground points' estimated heights
  std::vector<double> truth_m;      // per counted cell: std of their true heights
  ErrorStatistics thickness;        // over the counted cells (rmse, median)
  ErrorStatistics truth;
  size_t cells = 0;           // counted cells
  size_t points = 0;          // ground points of the counted cells
  size_t points_binned = 0;   // every point of the scans used
  size_t points_skipped = 0;  // not finite, or beyond the cell grid (2^20 cells from the origin)
  size_t scans = 0;           // scans used
  size_t scans_skipped = 0;   // no ground truth within max_dt on both sides of the stamp, or empty
  size_t scans_empty = 0;     // of scans_skipped: no points
};

/// A ground-truth pose at `t`: one stamped exactly `t`, else interpolated (slerp, linear) between
/// the poses on either side, each at most `max_dt` away. `gt` sorted by stamp. False without.
bool groundTruthAt(const Trajectory& gt, double t, double max_dt, Pose3* T);

/// The thickness of the ground in the scans' map against the ground truth `gt` (any order).
/// Throws std::invalid_argument on bad options.
GroundMapThickness groundMapThickness(const GroundScanSource& scans, const Trajectory& gt,
                                      const GroundMapOptions& options);

}  // namespace livo::evaluate
