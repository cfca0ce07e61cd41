// The coloured point map: one point per voxel (the first measured in it), each with a robust
// running-mean colour, the time it was last measured and the keyframe it is anchored to (so a
// loop correction can move it with that keyframe).
#pragma once

#include <cstdint>
#include <functional>
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
  /// Voxel key -> point id, open addressing with linear probing, grown at 50 % load: one lookup
  /// per scan point, several times faster than std::unordered_map at a few 100k points.
  class VoxelIndex {
   public:
    /// The id stored for key, after storing `id` for it if it had none (*inserted tells which).
    uint32_t findOrInsert(uint64_t key, uint32_t id, bool* inserted);
    /// Empties the index, sized for `expected` keys.
    void reset(size_t expected);

   private:
    static constexpr uint64_t kEmpty = ~uint64_t{0};  // voxel keys use 63 bits
    struct Slot {
      uint64_t key = kEmpty;
      uint32_t id = 0;
    };
    size_t home(uint64_t key) const { return static_cast<size_t>((key * 0x9E3779B97F4A7C15ull) >> 17) & (slots_.size() - 1); }
    void grow();
    std::vector<Slot> slots_;
    size_t size_ = 0;
  };

  uint64_t key(const Eigen::Vector3f& p) const;
  double voxel_;
  std::vector<MapPoint> points_;
  VoxelIndex index_;
  std::vector<uint32_t> remap_;
};

}  // namespace colour
}  // namespace livo
