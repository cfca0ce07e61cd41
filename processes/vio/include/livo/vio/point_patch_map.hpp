// The point-patch map (paper 2.3.2): LiDAR map points in a voxel hash (at most one per voxel),
// each with the patches (kStored^2 per pyramid level) it was observed in and the camera pose,
// time, exposure and photometric quality of each observation. Bounded: a radius around the camera
// and a point count (least recently seen first), a fixed number of patches per point.
#pragma once

#include <cstdint>
#include <vector>

#include "livo/flat_key_index.hpp"
#include "livo/so3.hpp"
#include "livo/vio/patch.hpp"
#include "livo/vio/reference_view.hpp"
#include "livo/vio/vio_options.hpp"
#include "livo/voxel_key.hpp"

namespace livo::vio {

struct PatchObservation {
  int64_t utime = 0;   // image time (IMU clock)
  ReferenceView view;  // the body pose, motion and calibration it was cut in
  // covariance of that pose's error [rotation (world frame), position] as the filter had it
  Eigen::Matrix<float, 6, 6> pose_cov_W = Eigen::Matrix<float, 6, 6>::Zero();
  float exposure_time = 0.0f;   // s, 0 if unknown
  float gradient = 0.0f;        // texture strength at capture (patchGradient, level 1)
  float error = 0.0f;           // residual RMS (grey levels) when last used as the reference
  std::vector<uint8_t> pixels;  // levels x kStored x kStored

  const uint8_t* level(int l) const { return pixels.data() + static_cast<size_t>(l) * kStoredArea; }
  Vec3 cameraCentre() const { return view.T_W_I * view.T_I_C.translation(); }
};

struct MapPoint {
  int64_t id = 0;                // unique, increasing: a deterministic tie-breaker
  Vec3 position = Vec3::Zero();  // W
  Vec3 normal = Vec3::Zero();    // W, unit: the surface's, from the LiDAR; zero if not known
  int64_t last_seen = 0;         // utime of the last image it was tracked in (or created)
  std::vector<PatchObservation> observations;
};

class PointPatchMap {
 public:
  explicit PointPatchMap(const MapOptions& options);

  /// Index of the point in p's voxel, or -1.
  int find(const Vec3& p) const;
  /// Adds a point in p's (free) voxel with its first observation and its surface normal (zero if
  /// not known); returns its index, -1 if taken.
  int add(const Vec3& p, int64_t utime, PatchObservation observation, const Vec3& normal = Vec3::Zero());
  /// Appends an observation, dropping the oldest beyond max_observations.
  void addObservation(int index, PatchObservation observation);

  /// Drops points farther than the radius from `centre` (checked once the centre moved a tenth of
  /// the radius since the last check), and when over max_points the least recently seen down to
  /// 90 % of it (hysteresis: the compaction runs every few images). Indices change.
  void prune(const Vec3& centre);
  /// Moves every point and observation pose by T (a loop correction T_corrected_odom). Points
  /// that come to share a voxel all stay; the older one is the voxel's.
  void transform(const Pose3& T);
  void clear();

  size_t size() const { return points_.size(); }
  const MapPoint& point(int i) const { return points_[static_cast<size_t>(i)]; }
  MapPoint& point(int i) { return points_[static_cast<size_t>(i)]; }
  const std::vector<MapPoint>& points() const { return points_; }
  size_t observationCount() const;
  /// Bytes held by points, patches and the index (approximate, for the memory bound).
  size_t memoryBytes() const;
  const MapOptions& options() const { return options_; }

 private:
  uint64_t keyOf(const Vec3& p) const;
  void reindex();

  MapOptions options_;
  double inv_voxel_;
  std::vector<MapPoint> points_;
  FlatKeyIndex index_;  // voxel key -> index into points_ (lookup only)
  int64_t next_id_ = 0;
  bool pruned_once_ = false;
  Vec3 pruned_at_ = Vec3::Zero();
};

}  // namespace livo::vio
