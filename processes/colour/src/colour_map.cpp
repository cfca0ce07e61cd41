#include "livo/colour/colour_map.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <type_traits>

#include "livo/voxel_key.hpp"

namespace livo::colour {

namespace {
// A map point as written to disk (the exact floats: it comes back as it was).
struct StoredPoint {
  float position[3];
  float colour[3];
  int32_t count;
  int32_t rejected;
  int64_t anchor;
};
static_assert(std::is_trivially_copyable<StoredPoint>::value && sizeof(StoredPoint) == 40, "written byte for byte");

StoredPoint stored(const MapPoint& p) {
  StoredPoint s;
  for (int k = 0; k < 3; ++k) s.position[k] = p.position[k], s.colour[k] = p.colour[k];
  s.count = p.count;
  s.rejected = p.rejected;
  s.anchor = p.anchor;
  return s;
}

MapPoint restored(const StoredPoint& s) {
  MapPoint p;
  p.position = Eigen::Vector3f(s.position[0], s.position[1], s.position[2]);
  p.colour = Eigen::Vector3f(s.colour[0], s.colour[1], s.colour[2]);
  p.count = s.count;
  p.rejected = s.rejected;
  p.anchor = s.anchor;
  return p;
}
}  // namespace

uint32_t ColourMap::VoxelIndex::findOrInsert(uint64_t key, uint32_t id, bool* inserted) {
  if (4 * (size_ + 1) > 3 * slots_.size()) grow();  // at 75 % load: 16 B a slot, a third of the map's memory at 50 %
  for (size_t i = home(key);; i = (i + 1) & (slots_.size() - 1)) {
    Slot& s = slots_[i];
    if (s.key == key) {
      *inserted = false;
      return s.id;
    }
    if (s.key == kEmpty) {
      s.key = key;
      s.id = id;
      ++size_;
      *inserted = true;
      return id;
    }
  }
}

void ColourMap::VoxelIndex::erase(uint64_t key) {
  const size_t mask = slots_.size() - 1;
  size_t i = home(key);
  while (slots_[i].key != key) {
    if (slots_[i].key == kEmpty) return;
    i = (i + 1) & mask;
  }
  // backward shift: move later entries of the probe run into the hole if their home allows it
  for (size_t j = (i + 1) & mask;; j = (j + 1) & mask) {
    if (slots_[j].key == kEmpty) break;
    const size_t h = home(slots_[j].key);
    // slot j's entry may move to i if i lies cyclically in [h, j)
    const bool movable = (j > i) ? (h <= i || h > j) : (h <= i && h > j);
    if (movable) {
      slots_[i] = slots_[j];
      i = j;
    }
  }
  slots_[i] = Slot{};
  --size_;
}

void ColourMap::VoxelIndex::reset(size_t expected, size_t most) {
  size_t n = 1024;
  while (n < 2 * expected + 2) n *= 2;
  if (most > 0) {
    // never more slots than the most keys need below the 75 % at which it grows: sized for half
    // load, a map near a 2.5 M point budget took 8 M slots (128 MB) where 4 M do
    size_t enough = 1024;
    while (4 * (std::max(most, expected) + 1) > 3 * enough) enough *= 2;
    n = std::min(n, enough);
  }
  if (n != slots_.size()) std::vector<Slot>().swap(slots_);  // the old table goes before the new one comes
  slots_.assign(n, Slot{});
  shift_ = 64 - __builtin_ctzll(n);
  size_ = 0;
}

void ColourMap::VoxelIndex::grow() {
  std::vector<Slot> old;
  old.swap(slots_);
  reset(old.size() / 2);  // twice the slots
  bool inserted = false;
  for (const Slot& s : old)
    if (s.key != kEmpty) findOrInsert(s.key, s.id, &inserted);
}

ColourMap::ColourMap(double voxel_size, TileOptions tiles)
    : voxel_(voxel_size > 0 ? voxel_size : 0.05), tile_options_(std::move(tiles)) {
  voxels_per_tile_ = std::max<int64_t>(1, std::llround(tile_options_.tile_size / voxel_));
  index_.reset(0);
}

ColourMap::Voxel ColourMap::voxelOf(const Eigen::Vector3f& p) const {
  // the voxel coordinate by division (not by the inverse size, as the LIO's and VIO's maps): a
  // point exactly on a voxel face stays in the voxel the map files were written with
  return {floorToInt(p.x() / voxel_), floorToInt(p.y() / voxel_), floorToInt(p.z() / voxel_)};
}

uint64_t ColourMap::key(const Eigen::Vector3f& p) const {
  const Voxel v = voxelOf(p);
  return packVoxel(v.x, v.y, v.z);
}

uint64_t ColourMap::tileKeyOf(const Voxel& v) const {
  auto t = [this](int64_t voxel) {
    const int64_t tile = voxel >= 0 ? voxel / voxels_per_tile_ : -((-voxel + voxels_per_tile_ - 1) / voxels_per_tile_);
    return static_cast<uint64_t>(static_cast<uint32_t>(static_cast<int32_t>(tile)));
  };
  return (t(v.x) << 32) | t(v.y);
}

uint32_t ColourMap::insertMerged(const MapPoint& p, Tile* tile, uint32_t slot) {
  const uint32_t next = slot != kNewSlot ? slot : free_.empty() ? static_cast<uint32_t>(points_.size()) : free_.back();
  bool inserted = false;
  const uint32_t id = index_.findOrInsert(key(p.position), next, &inserted);
  if (inserted) {
    if (slot != kNewSlot) {
      points_[id] = p;
    } else if (free_.empty()) {
      points_.push_back(p);
    } else {
      free_.pop_back();
      points_[id] = p;
    }
    tile->ids.push_back(id);
  } else {
    MapPoint& q = points_[id];
    const int n = q.count + p.count;
    if (n > 0) q.colour = (q.colour * float(q.count) + p.colour * float(p.count)) / float(n);
    q.count = n;
    q.rejected += p.rejected;
  }
  return id;
}

ColourMap::Tile& ColourMap::residentTile(uint64_t tile_key) {
  Tile& t = tiles_[tile_key];  // unordered_map: references stay valid as tiles are added
  if (t.spilled) reload(tile_key, &t);
  if (t.last_used < now_) t.last_used = now_;
  return t;
}

uint32_t ColourMap::addPoint(const Eigen::Vector3f& p, int64_t anchor, bool* created) {
  const Voxel v = voxelOf(p);
  Tile& tile = residentTile(tileKeyOf(v));
  return addToVoxel(packVoxel(v.x, v.y, v.z), p, anchor, &tile, created);
}

void ColourMap::addPoints(const std::vector<Eigen::Vector3f>& points, int64_t anchor, std::vector<uint32_t>* ids) {
  batch_keys_.resize(points.size());
  batch_tiles_.resize(points.size());
  for (size_t k = 0; k < points.size(); ++k) {
    const Voxel v = voxelOf(points[k]);
    batch_keys_[k] = packVoxel(v.x, v.y, v.z);
    batch_tiles_[k] = tileKeyOf(v);
  }
  ids->resize(points.size());
  // within the batch no tile leaves memory (only evictIdle and settleSpilledTiles send tiles to
  // disk) and the time is fixed, so a tile found resident and marked used stays so
  Tile* tile = nullptr;
  uint64_t tile_key = 0;
  for (size_t k = 0; k < points.size(); ++k) {
    if (k + kReadAhead < points.size()) index_.prefetch(batch_keys_[k + kReadAhead]);
    if (!tile || batch_tiles_[k] != tile_key) {
      tile_key = batch_tiles_[k];
      tile = &residentTile(tile_key);  // unordered_map: the reference stays valid as tiles are added
    }
    (*ids)[k] = addToVoxel(batch_keys_[k], points[k], anchor, tile, nullptr);
  }
}

uint32_t ColourMap::addToVoxel(uint64_t voxel_key, const Eigen::Vector3f& p, int64_t anchor, Tile* tile,
                               bool* created) {
  const uint32_t next = free_.empty() ? static_cast<uint32_t>(points_.size()) : free_.back();
  bool inserted = false;
  const uint32_t id = index_.findOrInsert(voxel_key, next, &inserted);
  if (inserted) {
    MapPoint mp;
    mp.position = p;
    mp.anchor = anchor;
    if (free_.empty()) {
      points_.push_back(mp);
    } else {
      free_.pop_back();
      points_[id] = mp;
    }
    tile->ids.push_back(id);
  }
  if (created) *created = inserted;
  return id;
}

size_t ColourMap::removeUncoloured(const std::function<bool(uint32_t)>& drop) {
  size_t removed = 0;
  for (uint32_t id = 0; id < points_.size(); ++id) {  // in id order: free_ is the same whatever the tiles' hash order
    MapPoint& p = points_[id];
    if (!p.live() || p.coloured() || !drop(id)) continue;
    index_.erase(key(p.position));
    p.rejected = -1;
    free_.push_back(id);
    ++removed;
  }
  if (removed == 0) return 0;
  for (auto& [k, t] : tiles_)
    if (!t.spilled)
      t.ids.erase(std::remove_if(t.ids.begin(), t.ids.end(), [this](uint32_t id) { return !points_[id].live(); }),
                  t.ids.end());
  return removed;
}

bool ColourMap::accumulate(uint32_t id, const Eigen::Vector3f& c, const AccumulationOptions& o) {
  MapPoint& mp = points_[id];
  if (mp.count >= o.outlier_min_count && (c - mp.colour).cwiseAbs().maxCoeff() > o.outlier_threshold) {
    ++mp.rejected;
    return false;
  }
  mp.count = std::min(mp.count + 1, std::max(1, o.max_count));
  mp.colour += (c - mp.colour) / static_cast<float>(mp.count);
  return true;
}

size_t ColourMap::colouredCount() const {
  size_t n = static_cast<size_t>(
      std::count_if(points_.begin(), points_.end(), [](const MapPoint& p) { return p.live() && p.coloured(); }));
  for (const auto& [k, t] : tiles_)
    if (t.spilled) n += t.spilled_coloured;
  return n;
}

size_t ColourMap::residentTiles() const {
  return static_cast<size_t>(
      std::count_if(tiles_.begin(), tiles_.end(), [](const auto& kt) { return !kt.second.spilled; }));
}

void ColourMap::transform(const std::function<bool(int64_t, Pose3*)>& delta) {
  Pose3 T;
  int64_t cached_anchor = INT64_MIN;
  bool cached_ok = false;
  size_t live = 0;
  for (MapPoint& p : points_) {
    if (!p.live()) continue;
    ++live;
    if (p.anchor != cached_anchor) {
      cached_anchor = p.anchor;
      cached_ok = delta(p.anchor, &T);
    }
    if (cached_ok) p.position = (T * p.position.cast<double>()).cast<float>();
  }
  // Re-index in place, merging points that now share a voxel; those that land in a tile on disk
  // join it there (a correction is no use of a tile: it neither comes back nor stays longer in
  // memory). The live points are compacted to the front in their order: slot `end` <= i, and a
  // point merges only into one already compacted, so no second copy of the map is needed.
  remap_.assign(points_.size(), kGone);
  free_.clear();
  index_.reset(live, tile_options_.max_resident_points);
  for (auto& [k, t] : tiles_)
    if (!t.spilled) t.ids.clear();
  std::map<uint64_t, std::vector<MapPoint>> to_disk;
  uint32_t end = 0;
  for (size_t i = 0; i < points_.size(); ++i) {
    if (!points_[i].live()) continue;
    const MapPoint p = points_[i];
    remap_[i] = placeMoved(p, &to_disk, end);
    if (remap_[i] == end) ++end;
  }
  points_.resize(end);
  ++epoch_;
  appendToDisk(to_disk);
}

uint32_t ColourMap::placeMoved(const MapPoint& p, std::map<uint64_t, std::vector<MapPoint>>* to_disk, uint32_t slot) {
  const uint64_t k = tileKey(p.position);
  auto it = tiles_.find(k);
  if (it != tiles_.end() && it->second.spilled) {
    (*to_disk)[k].push_back(p);
    return kGone;
  }
  // a tile that did not exist yet is created unused: it goes to disk at the next eviction
  Tile& tile = it != tiles_.end() ? it->second : tiles_[k];
  return insertMerged(p, &tile, slot);
}

void ColourMap::appendToDisk(const std::map<uint64_t, std::vector<MapPoint>>& to_disk) {
  for (const auto& [k, pts] : to_disk) appendRecord(&tiles_.at(k), pts);
}

void ColourMap::readTile(const Tile& tile, std::vector<MapPoint>* points) const {
  points->clear();
  std::vector<uint8_t> bytes;
  for (const SpillFile::Record& record : tile.records) {
    spill_->read(record, &bytes);
    uint64_t n_points = 0, n_anchors = 0;
    std::memcpy(&n_points, bytes.data(), 8);
    std::memcpy(&n_anchors, bytes.data() + 8, 8);
    const uint8_t* a = bytes.data() + 16;
    std::map<int64_t, Pose3> deltas;  // stored anchor pose -> current one
    for (uint64_t i = 0; i < n_anchors; ++i, a += 8 + 16 * 8) {
      int64_t anchor = 0;
      std::memcpy(&anchor, a, 8);
      Eigen::Matrix4d stored;
      std::memcpy(stored.data(), a + 8, 16 * 8);
      auto it = anchor_poses_.find(anchor);
      if (it == anchor_poses_.end() || (it->second.matrix() - stored).cwiseAbs().maxCoeff() < 1e-12) continue;
      Pose3 s;
      s.matrix() = stored;
      deltas[anchor] = it->second * s.inverse();
    }
    const size_t first = points->size();
    points->resize(first + n_points);
    for (uint64_t i = 0; i < n_points; ++i, a += sizeof(StoredPoint)) {
      StoredPoint sp;
      std::memcpy(&sp, a, sizeof(sp));
      (*points)[first + i] = restored(sp);
    }
    if (deltas.empty()) continue;
    for (size_t i = first; i < points->size(); ++i) {
      MapPoint& p = (*points)[i];
      auto it = deltas.find(p.anchor);
      if (it != deltas.end()) p.position = (it->second * p.position.cast<double>()).cast<float>();
    }
  }
}

void ColourMap::reload(uint64_t tile_key, Tile* tile) {
  std::vector<MapPoint> stored;
  readTile(*tile, &stored);
  const bool moved = tile->epoch < epoch_;
  tile->spilled = false;
  tile->spilled_coloured = 0;
  for (const SpillFile::Record& r : tile->records) spill_->release(r);  // the disk space goes back
  tile->records.clear();
  std::map<uint64_t, std::vector<MapPoint>> to_disk;
  for (const MapPoint& p : stored) {
    const uint32_t id = tileKey(p.position) == tile_key ? insertMerged(p, tile) : placeMoved(p, &to_disk);
    if (moved && id != kGone && p.coloured()) moved_on_reload_.push_back(id);
  }
  appendToDisk(to_disk);
}

void ColourMap::appendRecord(Tile* tile, const std::vector<MapPoint>& pts) {
  std::map<int64_t, Pose3> anchors;
  for (const MapPoint& p : pts) {
    auto it = anchor_poses_.find(p.anchor);
    if (it != anchor_poses_.end()) anchors.emplace(p.anchor, it->second);
  }
  if (!spill_) spill_ = std::make_unique<SpillFile>(tile_options_.spill_directory);
  std::vector<uint8_t> bytes(16 + anchors.size() * (8 + 16 * 8) + pts.size() * sizeof(StoredPoint));
  const uint64_t n_points = pts.size(), n_anchors = anchors.size();
  std::memcpy(bytes.data(), &n_points, 8);
  std::memcpy(bytes.data() + 8, &n_anchors, 8);
  uint8_t* a = bytes.data() + 16;
  for (const auto& [anchor, pose] : anchors) {
    std::memcpy(a, &anchor, 8);
    const Eigen::Matrix4d m = pose.matrix();
    std::memcpy(a + 8, m.data(), 16 * 8);
    a += 8 + 16 * 8;
  }
  for (const MapPoint& p : pts) {
    const StoredPoint sp = stored(p);
    std::memcpy(a, &sp, sizeof(sp));
    a += sizeof(sp);
  }
  if (tile->records.empty()) tile->epoch = epoch_;
  tile->records.push_back(spill_->append(bytes.data(), bytes.size()));
  tile->spilled = true;
  tile->spilled_coloured +=
      static_cast<size_t>(std::count_if(pts.begin(), pts.end(), [](const MapPoint& p) { return p.coloured(); }));
}

void ColourMap::spill(Tile* tile, std::vector<uint32_t>* freed) {
  // points never coloured are not kept: a scan that measures the voxel again creates it anew
  std::vector<MapPoint> pts;
  pts.reserve(tile->ids.size());
  for (uint32_t id : tile->ids) {
    MapPoint& p = points_[id];
    if (p.coloured()) pts.push_back(p);
    index_.erase(key(p.position));
    p.rejected = -1;
    free_.push_back(id);
    freed->push_back(id);
  }
  std::vector<uint32_t>().swap(tile->ids);
  if (pts.empty()) {
    tile->spilled = false;  // nothing to keep: the caller forgets the tile
    return;
  }
  appendRecord(tile, pts);
}

namespace {
void dropFreed(std::vector<uint32_t>* ids, std::vector<uint32_t> freed) {
  if (freed.empty() || ids->empty()) return;
  std::sort(freed.begin(), freed.end());
  ids->erase(std::remove_if(ids->begin(), ids->end(),
                            [&](uint32_t id) { return std::binary_search(freed.begin(), freed.end(), id); }),
             ids->end());
}
}  // namespace

std::vector<uint32_t> ColourMap::evictIdle(int64_t utime) {
  std::vector<uint32_t> freed;
  if (tile_options_.idle_s <= 0.0) return freed;
  const int64_t before = utime - static_cast<int64_t>(tile_options_.idle_s * 1e6);
  std::vector<uint64_t> idle;
  for (const auto& [k, t] : tiles_)
    if (!t.spilled && t.last_used < before) idle.push_back(k);
  std::sort(idle.begin(), idle.end());  // the same order whatever the hash table's
  for (uint64_t k : idle) {
    Tile& t = tiles_.at(k);
    spill(&t, &freed);
    if (!t.spilled) tiles_.erase(k);  // nothing coloured in it
  }
  evictForBudget(utime, 0, &freed);
  dropFreed(&moved_on_reload_, freed);
  return freed;
}

void ColourMap::evictForBudget(int64_t utime, size_t incoming, std::vector<uint32_t>* freed) {
  const size_t budget = tile_options_.max_resident_points;
  if (budget == 0 || residentPoints() + incoming <= budget) return;
  // over the budget: the least recently used tiles that no image can still need, oldest first
  const int64_t needed_from = utime - static_cast<int64_t>(tile_options_.min_idle_s * 1e6);
  std::vector<std::pair<int64_t, uint64_t>> lru;
  for (const auto& [k, t] : tiles_)
    if (!t.spilled && t.last_used < needed_from) lru.push_back({t.last_used, k});
  std::sort(lru.begin(), lru.end());
  for (const auto& [last_used, k] : lru) {
    if (residentPoints() + incoming <= budget) break;
    Tile& t = tiles_.at(k);
    spill(&t, freed);
    ++evicted_for_memory_;
    if (!t.spilled) tiles_.erase(k);
  }
}

std::vector<uint32_t> ColourMap::settleSpilledTiles() {
  std::vector<uint32_t> freed;
  // a tile brought back may append points to one settled before it: go round until none is left
  for (;;) {
    std::vector<uint64_t> stale;
    for (const auto& [k, t] : tiles_)
      if (unsettled(t)) stale.push_back(k);
    if (stale.empty()) break;
    std::sort(stale.begin(), stale.end());
    for (uint64_t k : stale) {
      if (!unsettled(tiles_.at(k))) continue;
      // room for it within the budget first (a save must not take more memory than the run)
      evictForBudget(now_, tiles_.at(k).spilled_coloured, &freed);
      Tile& t = tiles_.at(k);
      if (!unsettled(t)) continue;  // (evicting may have appended to it)
      reload(k, &t);
      spill(&t, &freed);
      if (!t.spilled) tiles_.erase(k);
    }
  }
  dropFreed(&moved_on_reload_, freed);
  return freed;
}

void ColourMap::forEachPoint(const std::function<void(const MapPoint&)>& visit) const {
  for (const MapPoint& p : points_)
    if (p.live()) visit(p);
  std::vector<uint64_t> spilled;
  for (const auto& [k, t] : tiles_)
    if (t.spilled) spilled.push_back(k);
  std::sort(spilled.begin(), spilled.end());
  std::vector<MapPoint> pts;
  for (uint64_t k : spilled) {
    readTile(tiles_.at(k), &pts);
    for (const MapPoint& p : pts) visit(p);
  }
}

std::vector<uint32_t> ColourMap::takeMovedOnReload() {
  std::vector<uint32_t> out;
  out.swap(moved_on_reload_);
  return out;
}

}  // namespace livo::colour
