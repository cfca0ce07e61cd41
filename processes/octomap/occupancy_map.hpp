// The OctoMap being built: an octomap::OcTree, or a ColorOcTree when colours are wanted, filled
// by ray casting from the sensor origin; written as .bt (binary occupancy, always an OcTree so
// every viewer reads it) and .ot (full, with colours); occupied leaves listed for evaluation.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "octomap_options.hpp"

namespace octomap {
class OcTree;
class ColorOcTree;
class AbstractOccupancyOcTree;
}  // namespace octomap

namespace livo {
namespace octomap_export {

class OccupancyMap {
 public:
  explicit OccupancyMap(const OctomapOptions& options);
  ~OccupancyMap();
  // movable (a builder starts a new map after an odometry reset), not copyable
  OccupancyMap(OccupancyMap&&) noexcept;
  OccupancyMap& operator=(OccupancyMap&&) noexcept;

  /// Casts a ray from `origin` to every point (world frame); non-finite points and points within
  /// min_range are skipped. Returns the number of rays inserted.
  size_t insertRays(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3d& origin);
  /// One sweep cast from several origins (time slices) as a single update: each slice casts one
  /// ray per endpoint voxel (to its centre); every voxel crossed by any ray of the sweep gets one
  /// miss unless it holds an endpoint of the sweep, and every endpoint voxel one hit, after the
  /// misses (octomap's insertPointCloud with discretize, merged over the slices). Returns the
  /// number of points taken (finite, in the tree's bounds, beyond min_range).
  struct Slice {
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();
    const std::vector<Eigen::Vector3f>* points = nullptr;
  };
  size_t insertSweep(const std::vector<Slice>& slices);
  struct Scratch;  // defined in the .cpp
  /// Colours occupied leaves (ColorOcTree only; otherwise a no-op returning 0).
  size_t setColours(const std::vector<Eigen::Vector3f>& points, const std::vector<std::array<uint8_t, 3>>& rgb);
  void clear();

  /// Occupancy of the leaf containing p: 1 occupied, 0 free, -1 unknown.
  int classify(const Eigen::Vector3d& p) const;
  /// Centres of occupied voxels at the finest resolution (pruned nodes expanded).
  std::vector<Eigen::Vector3d> occupiedVoxels() const;
  size_t leafCount() const;

  bool writeBinary(const std::string& path) const;  // .bt
  bool writeFull(const std::string& path) const;    // .ot
  /// The same as bytes (for the OCTOMAP message).
  std::string binaryBytes() const;
  std::string fullBytes() const;
  std::string treeType() const;

  const OctomapOptions& options() const { return options_; }

 private:
  const octomap::AbstractOccupancyOcTree& tree() const;
  std::unique_ptr<octomap::OcTree> occupancyOnly() const;  // for .bt of a colour tree
  void refreshInner() const;

  OctomapOptions options_;
  std::unique_ptr<Scratch> scratch_;  // key sets reused across sweeps
  std::unique_ptr<octomap::OcTree> plain_;
  std::unique_ptr<octomap::ColorOcTree> colour_;
  mutable bool inner_dirty_ = false;
};

}  // namespace octomap_export
}  // namespace livo
