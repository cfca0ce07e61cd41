#include "colour_map.hpp"

#include <algorithm>
#include <cmath>

namespace livo {
namespace colour {

ColourMap::ColourMap(double voxel_size) : voxel_(voxel_size > 0 ? voxel_size : 0.05) {}

uint64_t ColourMap::key(const Eigen::Vector3f& p) const {
  auto k = [this](float v) {
    return static_cast<uint64_t>(static_cast<int64_t>(std::floor(v / voxel_)) + (int64_t(1) << 20)) & 0x1FFFFF;
  };
  return (k(p.x()) << 42) | (k(p.y()) << 21) | k(p.z());
}

uint32_t ColourMap::addPoint(const Eigen::Vector3f& p, int64_t anchor, bool* created) {
  auto [it, inserted] = index_.emplace(key(p), static_cast<uint32_t>(points_.size()));
  if (inserted) {
    MapPoint mp;
    mp.position = p;
    mp.anchor = anchor;
    points_.push_back(mp);
  }
  if (created) *created = inserted;
  return it->second;
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
  index_.clear();
  for (size_t i = 0; i < points_.size(); ++i) {
    const MapPoint& p = points_[i];
    auto [it, inserted] = index_.emplace(key(p.position), static_cast<uint32_t>(kept.size()));
    if (inserted) {
      kept.push_back(p);
    } else {
      MapPoint& q = kept[it->second];
      const int n = q.count + p.count;
      if (n > 0) q.colour = (q.colour * float(q.count) + p.colour * float(p.count)) / float(n);
      q.count = n;
      q.rejected += p.rejected;
    }
    remap_[i] = it->second;
  }
  points_.swap(kept);
}

}  // namespace colour
}  // namespace livo
