// The OctoMap being built: an ::octomap::OcTree, or a ColorOcTree when colours are wanted, filled
// by ray casting from the sensor origin; written as .bt (binary occupancy, always an OcTree so
// every viewer reads it) and .ot (full, with colours); occupied leaves listed for evaluation.
//
// Memory: the octree is kept as tiles, cubes of 2^k voxels that are whole subtrees of the one
// tree (options.tile_size, rounded). Each tile is an octree of its own holding only its keys; a
// tile no ray has updated for tile_idle_s of sensor time is written to a scratch file (pruned
// first, for an OcTree: lossless) and leaves memory, and comes back when a ray reaches it again.
// The files are written tile by tile, as the one octree they make (octomap's formats, streamed:
// the levels above the tiles are made from the tiles' roots), so a map much larger than memory
// can still be written whole. Above the tiles nothing is pruned (the files stay valid octrees,
// a few nodes larger than octomap's own prune() would leave them).
#pragma once

#include <array>
#include <cstdint>
#include <iosfwd>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "livo/octomap/octomap_options.hpp"

namespace octomap {
class OcTree;
class AbstractOccupancyOcTree;
}  // namespace octomap

namespace livo {
class SpillFile;
}  // namespace livo

namespace livo::octomap {

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

  /// Sensor time of the updates that follow (a tile updated then is in use then).
  void setTime(int64_t utime) { now_ = utime; }
  /// Writes the tiles not updated since before now - tile_idle_s to disk, and (OcTree) prunes the
  /// next resident tile in turn, so clamped free space stays collapsed; returns the tiles written.
  size_t evictIdle();
  size_t residentTiles() const;
  size_t spilledTiles() const;
  uint64_t spilledBytes() const;  // the tiles on disk (the scratch file's live records)

  /// Occupancy of the leaf containing p: 1 occupied, 0 free, -1 unknown.
  int classify(const Eigen::Vector3d& p) const;
  /// Centres of occupied voxels at the finest resolution (pruned nodes expanded).
  std::vector<Eigen::Vector3d> occupiedVoxels() const;
  size_t leafCount() const;

  bool writeBinary(const std::string& path) const;  // .bt
  bool writeFull(const std::string& path) const;    // .ot
  /// The same as bytes; `resident_only`: only the tiles in memory (the OCTOMAP message: the area
  /// updated in the last tile_idle_s, bounded however large the map grows).
  std::string binaryBytes(bool resident_only = false) const;
  std::string fullBytes(bool resident_only = false) const;
  std::string treeType() const;

  const OctomapOptions& options() const { return options_; }

 private:
  struct Tile;
  enum class Format { kFull, kBinary };
  struct TileSummary;
  /// The tile of a key, brought back from disk if it is there, marked used now.
  Tile& residentTile(uint64_t tile_index);
  void spill(Tile* tile);
  /// A tile's tree: the resident one, or (for a tile on disk) one read back into `holder`.
  ::octomap::AbstractOccupancyOcTree& treeOf(const Tile& tile,
                                             std::unique_ptr<::octomap::AbstractOccupancyOcTree>* holder) const;
  std::unique_ptr<::octomap::AbstractOccupancyOcTree> newTree() const;
  void refreshResident() const;
  /// What the file needs of a tile: its root's data and subtree size, and (payload) its part of
  /// the file in `format`.
  TileSummary summarize(const ::octomap::AbstractOccupancyOcTree& tree, Format format, std::string* payload) const;
  /// The tiles to write (all, or the resident ones) summarized in `format`, in the tree's order.
  struct TileLevels;
  TileLevels tileLevels(Format format, bool resident_only) const;
  /// A tile's part of the file in `format`.
  void writeTilePayload(std::ostream& out, const TileSummary& s, Format format) const;
  /// Node (d, tiles [lo, hi)) of the levels above the tiles and its subtree, the tiles' parts in place.
  void writeLevel(std::ostream& out, const TileLevels& levels, size_t lo, size_t hi, int d, Format format) const;
  bool writeTree(std::ostream& out, Format format, bool resident_only) const;

  OctomapOptions options_;
  int tile_bits_ = 16;                               // a tile spans 2^tile_bits_ keys per axis
  std::unique_ptr<::octomap::OcTree> keys_;          // empty: the key arithmetic (same resolution)
  std::unique_ptr<Scratch> scratch_;                 // key sets reused across sweeps
  std::map<uint64_t, std::unique_ptr<Tile>> tiles_;  // by tile index
  std::unique_ptr<SpillFile> spill_;
  int64_t now_ = INT64_MIN;
  uint64_t prune_next_ = 0;  // tile index the round-robin pruning goes on from
};

}  // namespace livo::octomap
