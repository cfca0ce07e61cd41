// Voxel-grid downsampling: one centroid per occupied voxel, in a deterministic order.
#pragma once

#include "livo/loop/point_types.hpp"

namespace livo::loop {

/// Drops non-finite points and replaces the points of each cubic voxel of edge `voxel_size` by
/// their centroid. Output is ordered by voxel index (independent of input order).
/// voxel_size <= 0 only removes non-finite points.
Points centroidPerVoxel(const Points& points, double voxel_size);

}  // namespace livo::loop

#include <cstdint>
#include <unordered_map>

namespace livo::loop {

/// centroidPerVoxel over a stream: points are added one at a time (non-finite ones dropped) and
/// only per-voxel sums are kept, so memory grows with the voxels, not the points. centroids()
/// equals centroidPerVoxel of every point added, in the order added.
class VoxelCentroids {
 public:
  explicit VoxelCentroids(double voxel_size) : voxel_(voxel_size) {}
  void add(const Vec3& p);
  Points centroids() const;
  size_t voxels() const { return voxel_ > 0 ? sums_.size() : all_.size(); }

 private:
  struct Key {
    int64_t x, y, z;
    bool operator==(const Key& o) const { return x == o.x && y == o.y && z == o.z; }
  };
  struct KeyHash {
    size_t operator()(const Key& k) const {
      return static_cast<size_t>((uint64_t(k.x) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(k.y) * 0xC2B2AE3D27D4EB4Full) ^
                                 (uint64_t(k.z) * 0x165667B19E3779F9ull));
    }
  };
  struct Sum {
    Vec3 sum = Vec3::Zero();
    int64_t count = 0;
  };
  double voxel_;
  std::unordered_map<Key, Sum, KeyHash> sums_;
  Points all_;  // voxel_size <= 0: every finite point
};

}  // namespace livo::loop
