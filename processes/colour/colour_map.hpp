// The coloured point map: one point per voxel (the first measured in it), each with a robust
// running-mean colour, the time it was last measured and the keyframe it is anchored to (so a
// loop correction can move it with that keyframe).
#pragma once

#include <cstdint>
#include <functional>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "livo/so3.hpp"

namespace livo {
namespace colour {

struct MapPoint {
  Eigen::Vector3f position = Eigen::Vector3f::Zero();  // world frame
  Eigen::Vector3f colour = Eigen::Vector3f::Zero();    // running mean, 0..255 (exposure-normalised)
  int32_t count = 0;           // accepted observations
  int32_t rejected = 0;        // observations refused as outliers
  int64_t anchor = -1;         // keyframe id it moves with (-1: none)
  uint32_t visit = 0;          // scratch marker (which image last looked at it)
  bool coloured() const { return count > 0; }
};

struct AccumulationOptions {
  double outlier_threshold = 60.0;
  int outlier_min_count = 3;
  int max_count = 50;
};

class ColourMap {
 public:
  explicit ColourMap(double voxel_size);

  /// The point of the voxel containing p (created at p if the voxel is empty).
  uint32_t addPoint(const Eigen::Vector3f& p, int64_t anchor, bool* created = nullptr);
  /// Robust running mean; false if the observation was refused as an outlier.
  bool accumulate(uint32_t id, const Eigen::Vector3f& colour, const AccumulationOptions& options);

  /// Moves points by the delta of their anchor (`delta(anchor, &T)` false: leave them) and
  /// re-indexes the voxels; points that land in an occupied voxel are merged (colours weighted).
  void transform(const std::function<bool(int64_t anchor, Pose3* delta)>& delta);

  const std::vector<MapPoint>& points() const { return points_; }
  MapPoint& point(uint32_t id) { return points_[id]; }
  const MapPoint& point(uint32_t id) const { return points_[id]; }
  size_t size() const { return points_.size(); }
  size_t colouredCount() const;
  double voxelSize() const { return voxel_; }
  /// Ids of points removed by the last transform() merge are remapped here (old id -> new id).
  const std::vector<uint32_t>& lastRemap() const { return remap_; }

 private:
  uint64_t key(const Eigen::Vector3f& p) const;
  double voxel_;
  std::vector<MapPoint> points_;
  std::unordered_map<uint64_t, uint32_t> index_;
  std::vector<uint32_t> remap_;
};

}  // namespace colour
}  // namespace livo
