// The LiDAR map: a hashed voxel grid with a bounded number of points per voxel (like KISS-ICP's
// VoxelHashMap), exact k-nearest-neighbour search within a radius, insertion under a
// minimum-spacing downsampling rule, removal of voxels outside a moving local window, and removal
// of points that later beams pass through (something moved away, or an early pose was off).
#pragma once

#include <cstdint>
#include <vector>

#include "livo/flat_key_index.hpp"
#include "livo/voxel_downsample.hpp"
#include "livo/worker_threads.hpp"

namespace livo::lio {

struct VoxelMapOptions {
  double voxel_size = 1.0;           // m, edge of a hash voxel
  int max_points_per_voxel = 20;     // a full voxel takes no more points
  double min_point_distance = 0.4;   // m, a new point this close to one in its voxel is dropped
  double seen_again_distance = 0.1;  // m, a new point this close to a stored one is a new sighting
                                     // of it (SeenThroughOptions)
  // Refresh: a point seen from a range below this fraction of the range a stored point was seen
  // from replaces it (the stored point within min_point_distance of it or, in a full voxel, the one
  // seen from farthest): range noise, beam footprint and grazing smear all grow with range, so the
  // map converges to its best-observed points instead of keeping the first (in a corridor walked
  // forward, every wall is first seen far away and at grazing incidence). 0: first points stay.
  double refresh_range_ratio = 0.5;
};

/// Free-space carving: a stored point that beams pass through in `misses_to_remove` sweeps, with
/// no new point landing near it in between, is removed (a parked car that left, a pedestrian, a
/// point placed by an early pose that was off). A beam passes through a point when the point lies
/// within the beam's radius (radius + divergence * distance) of the ray and nearer than the beam's
/// return by more than the margin (max(end_margin, end_margin_fraction * range)): the margin keeps
/// the surface the beam hits, and the floor a beam grazes on its way there, out of the test.
struct SeenThroughOptions {
  bool enabled = true;
  double beam_radius = 0.03;         // m at the sensor
  double beam_divergence = 0.003;    // rad (VLP-16: 3 mrad horizontal)
  double end_margin = 1.0;           // m
  double end_margin_fraction = 0.2;  // of the beam's range
  double min_range = 1.0;            // m, points nearer the sensor are not tested
  double max_range = 40.0;           // m, longer beams are not cast
  int misses_to_remove = 3;          // sweeps seeing through a point before it goes
  int ray_stride = 4;                // every n-th beam of a sweep is cast
};

class VoxelMap {
 public:
  explicit VoxelMap(VoxelMapOptions options = {});

  /// Adds points under the downsampling rule; returns how many were stored. Points given without
  /// the sensor position they were seen from count as seen from range 0 (never refreshed).
  size_t insert(const std::vector<Vec3>& points);
  bool insert(const Vec3& p);
  /// Same for the points of one sweep seen from `origin`, refreshing worse-observed stored points
  /// (VoxelMapOptions::refresh_range_ratio); returns how many were stored or replaced one.
  size_t insert(const std::vector<Vec3>& points, const Vec3& origin);
  bool insert(const Vec3& p, double range);

  /// Up to k nearest stored points within max_distance of q (exact), nearest first; returns the
  /// count. out_points / out_sq_dist must hold k entries. Requires k <= 32.
  int knn(const Vec3& q, int k, double max_distance, Vec3* out_points, double* out_sq_dist) const;

  /// Casts the beams from `origin` (world) to every `ray_stride`-th of `endpoints` (one sweep)
  /// and removes the points seen through in `misses_to_remove` sweeps (see SeenThroughOptions).
  /// Returns how many points were removed.
  /// With `threads`, the beams are cast on them (the same points are removed).
  size_t removeSeenThrough(const Vec3& origin, const std::vector<Vec3>& endpoints, const SeenThroughOptions& options,
                           WorkerThreads* threads = nullptr);

  /// Drops voxels whose centre is farther than radius from centre (the local window); returns
  /// how many voxels were removed.
  size_t removeFarFrom(const Vec3& centre, double radius);

  /// Moves every stored point by T (a change of world frame), keeping the range each was seen
  /// from; the seen-through counts start again. Points that land in one new voxel closer than
  /// min_point_distance are thinned as on insertion.
  void transform(const Pose3& T);

  void clear();
  bool empty() const { return voxels_.empty(); }
  size_t numVoxels() const { return voxels_.size(); }
  size_t numPoints() const;
  /// Every stored point (tests, rebuilds).
  std::vector<Vec3> points() const;
  const VoxelMapOptions& options() const { return options_; }

 private:
  struct Voxel {
    VoxelKey key;
    int32_t count;
    int32_t cx, cy, cz;  // integer coordinates
  };
  const float* voxelPoints(int32_t v) const { return &pool_[static_cast<size_t>(v) * stride_]; }
  float* voxelPoints(int32_t v) { return &pool_[static_cast<size_t>(v) * stride_]; }
  uint8_t* voxelMisses(int32_t v) { return &misses_[static_cast<size_t>(v) * options_.max_points_per_voxel]; }
  float* voxelRanges(int32_t v) { return &ranges_[static_cast<size_t>(v) * options_.max_points_per_voxel]; }
  void removePoint(int32_t v, int i);
  // knn's stages (voxel_map.cpp defines the structs)
  struct KnnResult;
  struct KnnBox;
  struct KnnStage;
  /// Offers voxel `key`'s points to the k nearest so far.
  void scanVoxel(VoxelKey key, const Vec3& q, KnnResult* best) const;
  /// The voxels within stage_r of q that may hold points, less those an earlier stage visited (in
  /// `inner` within sqrt(inner2)), into the stage's order.
  void stageCandidates(const Vec3& q, double stage_r, const KnnBox& inner, double inner2, KnnStage* stage) const;
  /// Visits the stage's voxels nearest first until the rest are farther than the k-th nearest.
  void visitNearestFirst(KnnStage* stage, const Vec3& q, KnnResult* best) const;
  /// False if no voxel with this key is stored; true if one may be (see occupied_).
  bool mayHold(VoxelKey key) const {
    const uint64_t bit = (key * 0x9e3779b97f4a7c15ULL) >> (64 - kOccupiedBits);
    return (occupied_[bit >> 6] >> (bit & 63)) & 1;
  }
  void markOccupied(VoxelKey key) {
    const uint64_t bit = (key * 0x9e3779b97f4a7c15ULL) >> (64 - kOccupiedBits);
    occupied_[bit >> 6] |= uint64_t{1} << (bit & 63);
  }
  /// Flags voxel v's points that the ray origin + t dir (t <= reach) passes through this sweep.
  void markSeenThrough(int32_t v, const Vec3& origin, const Vec3& dir, double reach, const SeenThroughOptions& o,
                       std::vector<int32_t>* touched);
  /// Calls visit(v, dir, reach) for every stored voxel v within the radius of beams [first_beam,
  /// end_beam) (every ray_stride-th endpoint); a voxel may come more than once.
  template <typename VisitVoxel>
  void forEachVoxelNearBeams(const Vec3& origin, const std::vector<Vec3>& endpoints, const SeenThroughOptions& o,
                             size_t first_beam, size_t end_beam, VisitVoxel visit) const;

  VoxelMapOptions options_;
  double inv_size_;
  size_t stride_;  // floats per voxel: 3 * max_points_per_voxel
  std::vector<Voxel> voxels_;
  std::vector<float> pool_;      // voxel v's points at [v * stride_, v * stride_ + 3 * count)
  std::vector<uint8_t> misses_;  // per point slot: sweeps that saw through it since it was last seen;
                                 // the high bit marks "seen through in the current sweep"
  std::vector<float> ranges_;    // per point slot: the range it was seen from (refresh)
  FlatKeyIndex index_;
  // A bit per hashed key, set for every stored voxel: most voxels a beam or a kNN ball meets are
  // empty, and a bit in a table that stays in the L1 cache rules those out without probing the
  // index (a set bit may be another key's: then the index decides).
  static constexpr int kOccupiedBits = 16;
  std::vector<uint64_t> occupied_ = std::vector<uint64_t>(size_t{1} << (kOccupiedBits - 6), 0);
};

}  // namespace livo::lio
