#include "colour_map.hpp"

#include <algorithm>
#include <cmath>

namespace livo {
namespace colour {

uint32_t ColourMap::VoxelIndex::findOrInsert(uint64_t key, uint32_t id, bool* inserted) {
  if (2 * (size_ + 1) > slots_.size()) grow();
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

void ColourMap::VoxelIndex::reset(size_t expected) {
  size_t n = 1024;
  while (n < 2 * expected + 2) n *= 2;
  slots_.assign(n, Slot{});
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

ColourMap::ColourMap(double voxel_size) : voxel_(voxel_size > 0 ? voxel_size : 0.05) { index_.reset(0); }

uint64_t ColourMap::key(const Eigen::Vector3f& p) const {
  auto k = [this](float v) {
    return static_cast<uint64_t>(static_cast<int64_t>(std::floor(v / voxel_)) + (int64_t(1) << 20)) & 0x1FFFFF;
  };
  return (k(p.x()) << 42) | (k(p.y()) << 21) | k(p.z());
}

uint32_t ColourMap::addPoint(const Eigen::Vector3f& p, int64_t anchor, bool* created) {
  bool inserted = false;
  const uint32_t id = index_.findOrInsert(key(p), static_cast<uint32_t>(points_.size()), &inserted);
  if (inserted) {
    MapPoint mp;
    mp.position = p;
    mp.anchor = anchor;
    points_.push_back(mp);
  }
  if (created) *created = inserted;
  return id;
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
  return static_cast<size_t>(std::count_if(points_.begin(), points_.end(), [](const MapPoint& p) { return p.coloured(); }));
}

void ColourMap::transform(const std::function<bool(int64_t, Pose3*)>& delta) {
  Pose3 T;
  int64_t cached_anchor = INT64_MIN;
  bool cached_ok = false;
  for (MapPoint& p : points_) {
    if (p.anchor != cached_anchor) {
      cached_anchor = p.anchor;
      cached_ok = delta(p.anchor, &T);
    }
    if (cached_ok) p.position = (T * p.position.cast<double>()).cast<float>();
  }
  // re-index, merging points that now share a voxel
  std::vector<MapPoint> kept;
  kept.reserve(points_.size());
  remap_.assign(points_.size(), 0);
  index_.reset(points_.size());
  for (size_t i = 0; i < points_.size(); ++i) {
    const MapPoint& p = points_[i];
    bool inserted = false;
    const uint32_t id = index_.findOrInsert(key(p.position), static_cast<uint32_t>(kept.size()), &inserted);
    if (inserted) {
      kept.push_back(p);
    } else {
      MapPoint& q = kept[id];
      const int n = q.count + p.count;
      if (n > 0) q.colour = (q.colour * float(q.count) + p.colour * float(p.count)) / float(n);
      q.count = n;
      q.rejected += p.rejected;
    }
    remap_[i] = id;
  }
  points_.swap(kept);
}

}  // namespace colour
}  // namespace livo
