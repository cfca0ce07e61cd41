// The coloured point map: one point per voxel (the first measured in it), each with a robust
// running-mean colour, the time it was last measured and the keyframe it is anchored to (so a
// loop correction can move it with that keyframe).
//
// Memory: the voxels are grouped into square tiles (tile_size metres in x and y, all heights).
// A tile that has taken no scan point for idle_s of sensor time goes to disk (a SpillFile) and its
// points leave memory; a scan point falling into it brings it back. A loop correction moves the
// resident points at once; a tile on disk keeps, per anchor, the keyframe pose its points were
// stored at and is moved when it comes back (or for the files: settleSpilledTiles()), so every
// voxel still holds one point whatever was on disk. Neither a correction nor a tile coming back
// brings a tile on disk back or counts as its use: points they move into one are appended to it
// on disk (another record, merged when it comes back).
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "livo/so3.hpp"
#include "livo/spill_file.hpp"

namespace livo::colour {

struct MapPoint {
  Eigen::Vector3f position = Eigen::Vector3f::Zero();  // world frame
  Eigen::Vector3f colour = Eigen::Vector3f::Zero();    // running mean, 0..255 (exposure-normalised)
  int32_t count = 0;                                   // accepted observations
  int32_t rejected = 0;                                // observations refused as outliers (-1: a free slot)
  int64_t anchor = -1;                                 // keyframe id it moves with (-1: none)
  bool coloured() const { return count > 0; }
  bool live() const { return rejected >= 0; }
};

struct AccumulationOptions {
  double outlier_threshold = 60.0;
  int outlier_min_count = 3;
  int max_count = 50;
};

struct TileOptions {
  double tile_size = 16.0;      // m, rounded to whole voxels
  double idle_s = 10.0;         // sensor time without a new point before a tile goes to disk (0: never)
  std::string spill_directory;  // "" : the temp directory
  /// Resident points above which the least recently used tiles go to disk before they are idle_s
  /// idle (0: no limit), but none used within the last `min_idle_s` (the scans an image may still
  /// need). Where the route passes again and again, the tiles of the idle window hold more points
  /// with every pass; this keeps the memory flat, at the price of bringing tiles back more often.
  size_t max_resident_points = 0;
  double min_idle_s = 0.0;
};

class ColourMap {
 public:
  explicit ColourMap(double voxel_size, TileOptions tiles = {});

  /// The time scan points are added at (the tiles they touch are "used" then).
  void setTime(int64_t utime) { now_ = utime; }
  /// The point of the voxel containing p (created at p if the voxel is empty); a tile on disk
  /// comes back first.
  uint32_t addPoint(const Eigen::Vector3f& p, int64_t anchor, bool* created = nullptr);
  /// addPoint(points[k], anchor) for every k in order, the ids into `ids` (the same map and ids as
  /// one call per point). A scan's worth at once: each voxel is hashed once, the index (too large
  /// for the cache) is read a few points ahead, and a run of points in one tile finds it once.
  void addPoints(const std::vector<Eigen::Vector3f>& points, int64_t anchor, std::vector<uint32_t>* ids);
  /// Removes the resident points never coloured for which `drop(id)` is true (their voxels become
  /// empty: a scan that measures one again creates its point anew); returns how many. One pass
  /// over the resident points and tiles: call it now and then, not per scan.
  size_t removeUncoloured(const std::function<bool(uint32_t id)>& drop);
  /// Robust running mean; false if the observation was refused as an outlier.
  bool accumulate(uint32_t id, const Eigen::Vector3f& colour, const AccumulationOptions& options);

  /// The pose the map's points of `anchor` are in (set on a keyframe and by every correction).
  void setAnchorPose(int64_t anchor, const Pose3& T_W_I) { anchor_poses_[anchor] = T_W_I; }
  /// Moves resident points by the delta of their anchor (`delta(anchor, &T)` false: leave them)
  /// and re-indexes the voxels; points that land in an occupied voxel are merged (colours
  /// weighted), points that land in a tile on disk go to disk with it (lastRemap(): kGone).
  /// Call setAnchorPose for the moved anchors first: tiles on disk follow them.
  void transform(const std::function<bool(int64_t anchor, Pose3* delta)>& delta);

  /// Writes the tiles unused since before `utime - idle_s` to disk (their coloured points: one
  /// never coloured is measured anew if a scan comes back to it), then, while more than
  /// max_resident_points are resident, the least recently used ones unused since before
  /// `utime - min_idle_s`; returns the ids freed.
  std::vector<uint32_t> evictIdle(int64_t utime);
  /// Brings back, one at a time, the tiles on disk whose anchors moved since they were written or
  /// that took points from elsewhere, merges them and writes them out again (the files then hold
  /// one point per voxel); returns the ids freed.
  std::vector<uint32_t> settleSpilledTiles();
  /// Every point, resident and on disk (on disk: moved to the current anchor poses).
  void forEachPoint(const std::function<void(const MapPoint&)>& visit) const;
  /// Ids of points that came back from disk moved by a correction since the last call.
  std::vector<uint32_t> takeMovedOnReload();

  /// Resident slots (a free slot has live() false). A deque: the map grows a block at a time,
  /// never by reallocating (a vector reserves up to twice the points it holds, and holds the old
  /// and the new array at once while it grows).
  const std::deque<MapPoint>& points() const { return points_; }
  MapPoint& point(uint32_t id) { return points_[id]; }
  const MapPoint& point(uint32_t id) const { return points_[id]; }
  size_t size() const { return points_.size(); }
  /// Coloured points, resident and on disk.
  size_t colouredCount() const;
  size_t residentPoints() const { return points_.size() - free_.size(); }
  size_t residentTiles() const;
  /// The voxel index's bytes (16 a slot, a power of two of slots).
  size_t indexBytes() const { return index_.bytes(); }
  size_t spilledTiles() const { return tiles_.size() - residentTiles(); }
  /// Tiles that went to disk before they were idle_s idle (max_resident_points), so far.
  size_t tilesEvictedForMemory() const { return evicted_for_memory_; }
  /// Bytes of the tiles on disk (the scratch file's live records).
  uint64_t spilledBytes() const { return spill_ ? spill_->liveBytes() : 0; }
  /// Bytes written to the scratch file so far (tiles come back and go again).
  uint64_t spillWrittenBytes() const { return spill_ ? spill_->size() : 0; }
  double voxelSize() const { return voxel_; }
  /// The last transform()'s ids: old id -> new id (merged points share one), kGone for points
  /// that went to a tile on disk.
  const std::vector<uint32_t>& lastRemap() const { return remap_; }
  static constexpr uint32_t kGone = ~uint32_t{0};

 private:
  /// Voxel key -> point id, open addressing with linear probing, grown at 75 % load (sized for
  /// 50 % after a reset): one lookup per scan point, several times faster than
  /// std::unordered_map at a few 100k points.
  class VoxelIndex {
   public:
    /// The id stored for key, after storing `id` for it if it had none (*inserted tells which).
    uint32_t findOrInsert(uint64_t key, uint32_t id, bool* inserted);
    void prefetch(uint64_t key) const { __builtin_prefetch(&slots_[home(key)]); }
    /// Removes key (backward-shift deletion: no tombstones).
    void erase(uint64_t key);
    /// Empties the index, sized for `expected` keys at half load, but (most > 0: the resident
    /// points' budget) no larger than `most` keys need below the load it grows at.
    void reset(size_t expected, size_t most = 0);
    size_t bytes() const { return slots_.size() * sizeof(Slot); }

   private:
    static constexpr uint64_t kEmpty = ~uint64_t{0};  // voxel keys use 63 bits
    struct Slot {
      uint64_t key = kEmpty;
      uint32_t id = 0;
    };
    // Fibonacci hashing: the product's top bits, which every bit of the key reaches (its middle
    // bits, as used before, saw nothing of z, the key's top field: a wall's voxels, one column of
    // z each, shared their slots and probed through long runs)
    size_t home(uint64_t key) const { return static_cast<size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_); }
    void grow();
    std::vector<Slot> slots_;
    size_t size_ = 0;
    int shift_ = 63;  // 64 - log2(slots_.size()) (set by reset)
  };
  struct Tile {
    std::vector<uint32_t> ids;  // resident points
    int64_t last_used = INT64_MIN;
    bool spilled = false;
    // on disk: records of points with their anchors' poses; the first is the tile as it was
    // written, later ones points a correction or another tile's return moved into it (their
    // voxels may repeat: merged when it comes back)
    std::vector<SpillFile::Record> records;
    size_t spilled_coloured = 0;
    uint64_t epoch = 0;  // transform()s before its first record was written (behind epoch_: stale)
  };

  struct Voxel {
    int64_t x, y, z;
  };
  Voxel voxelOf(const Eigen::Vector3f& p) const;
  uint64_t key(const Eigen::Vector3f& p) const;
  uint64_t tileKey(const Eigen::Vector3f& p) const { return tileKeyOf(voxelOf(p)); }
  /// The tile of a voxel (not of a point), so that a voxel lies in exactly one tile.
  uint64_t tileKeyOf(const Voxel& v) const;
  /// addPoint's insertion once the voxel's key and its (resident, used) tile are known.
  uint32_t addToVoxel(uint64_t voxel_key, const Eigen::Vector3f& p, int64_t anchor, Tile* tile, bool* created);
  static constexpr uint32_t kNewSlot = ~uint32_t{0};
  static constexpr size_t kReadAhead = 8;  // addPoints starts each index read this many points early
  /// Inserts a point (a new voxel, or merged into the voxel's point); its tile must be resident.
  /// A new voxel's point goes to `slot` (overwritten; kNewSlot: a free slot or the end).
  uint32_t insertMerged(const MapPoint& p, Tile* tile, uint32_t slot = kNewSlot);
  /// The tile, brought back from disk if it was there, and marked used now.
  Tile& residentTile(uint64_t tile_key);
  /// Inserts a point moved by a correction or a reload: into its tile if resident (not marking
  /// it used; a new voxel's point to `slot` as in insertMerged), else into `to_disk` for that
  /// tile (returns kGone).
  uint32_t placeMoved(const MapPoint& p, std::map<uint64_t, std::vector<MapPoint>>* to_disk, uint32_t slot = kNewSlot);
  /// Appends points (at their anchors' current poses) to a tile's records on disk.
  void appendRecord(Tile* tile, const std::vector<MapPoint>& points);
  void appendToDisk(const std::map<uint64_t, std::vector<MapPoint>>& to_disk);
  void reload(uint64_t tile_key, Tile* tile);
  void spill(Tile* tile, std::vector<uint32_t>* freed);
  /// Writes the least recently used tiles not used since `utime - min_idle_s` to disk until
  /// `incoming` more points fit in max_resident_points (0: no budget).
  void evictForBudget(int64_t utime, size_t incoming, std::vector<uint32_t>* freed);
  void readTile(const Tile& tile, std::vector<MapPoint>* points) const;
  bool unsettled(const Tile& t) const { return t.spilled && (t.epoch < epoch_ || t.records.size() > 1); }

  double voxel_;
  int64_t voxels_per_tile_;
  TileOptions tile_options_;
  int64_t now_ = INT64_MIN;
  std::deque<MapPoint> points_;
  std::vector<uint32_t> free_;
  VoxelIndex index_;
  std::unordered_map<uint64_t, Tile> tiles_;
  std::map<int64_t, Pose3> anchor_poses_;
  std::unique_ptr<SpillFile> spill_;
  std::vector<uint32_t> remap_;
  std::vector<uint64_t> batch_keys_, batch_tiles_;  // addPoints' working set, kept between scans
  std::vector<uint32_t> moved_on_reload_;
  uint64_t epoch_ = 0;  // transform()s so far
  size_t evicted_for_memory_ = 0;
};

}  // namespace livo::colour
