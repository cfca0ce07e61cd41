// The LiDAR map: a hashed voxel grid with a bounded number of points per voxel (like KISS-ICP's
// VoxelHashMap), exact k-nearest-neighbour search within a radius, insertion under a
// minimum-spacing downsampling rule, and removal of voxels outside a moving local window.
#pragma once

#include <cstdint>
#include <vector>

#include "livo/lio/voxel_key.hpp"

namespace livo::lio {

struct VoxelMapOptions {
  double voxel_size = 1.0;         // m, edge of a hash voxel
  int max_points_per_voxel = 20;   // a full voxel takes no more points
  double min_point_distance = 0.4; // m, a new point this close to one in its voxel is dropped
};

class VoxelMap {
 public:
  explicit VoxelMap(VoxelMapOptions options = {});

  /// Adds points under the downsampling rule; returns how many were stored.
  size_t insert(const std::vector<Vec3>& points);
  bool insert(const Vec3& p);

  /// Up to k nearest stored points within max_distance of q (exact), nearest first; returns the
  /// count. out_points / out_sq_dist must hold k entries. Requires k <= 32.
  int knn(const Vec3& q, int k, double max_distance, Vec3* out_points, double* out_sq_dist) const;

  /// Drops voxels whose centre is farther than radius from centre (the local window); returns
  /// how many voxels were removed.
  size_t removeFarFrom(const Vec3& centre, double radius);

  void clear();
  bool empty() const { return voxels_.empty(); }
  size_t numVoxels() const { return voxels_.size(); }
  size_t numPoints() const;
  /// Every stored point (tests, rebuilds).
  std::vector<Vec3> points() const;
  const VoxelMapOptions& options() const { return opts_; }

 private:
  struct Voxel {
    VoxelKey key;
    int32_t count;
    int32_t cx, cy, cz;  // integer coordinates
  };
  const float* voxelPoints(int32_t v) const { return &pool_[static_cast<size_t>(v) * stride_]; }
  float* voxelPoints(int32_t v) { return &pool_[static_cast<size_t>(v) * stride_]; }

  VoxelMapOptions opts_;
  double inv_size_;
  size_t stride_;            // floats per voxel: 3 * max_points_per_voxel
  std::vector<Voxel> voxels_;
  std::vector<float> pool_;  // voxel v's points at [v * stride_, v * stride_ + 3 * count)
  FlatKeyIndex index_;
  std::vector<int> offsets_; // 27 neighbour offsets as (dx, dy, dz) triples, search radius 1
};

/// Indices of the first point falling in each voxel of the given size, in input order.
std::vector<size_t> voxelDownsample(const std::vector<Vec3>& points, double voxel_size);
/// Same on a subset of indices.
std::vector<size_t> voxelDownsample(const std::vector<Vec3>& points, const std::vector<size_t>& subset,
                                    double voxel_size);

}  // namespace livo::lio
