#include "livo/loop/voxel_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>

namespace livo::loop {

Points transformed(const Points& points, const Pose3& T) {
  Points out;
  out.reserve(points.size());
  for (const Vec3& p : points) out.push_back(T * p);
  return out;
}

Points centroidPerVoxel(const Points& points, double voxel_size) {
  Points finite;
  finite.reserve(points.size());
  for (const Vec3& p : points)
    if (p.allFinite()) finite.push_back(p);
  if (voxel_size <= 0.0 || finite.empty()) return finite;

  struct Keyed {
    int64_t x, y, z;
    uint32_t index;
  };
  std::vector<Keyed> keyed;
  keyed.reserve(finite.size());
  const double inv = 1.0 / voxel_size;
  for (size_t i = 0; i < finite.size(); ++i) {
    const Vec3& p = finite[i];
    keyed.push_back({static_cast<int64_t>(std::floor(p.x() * inv)), static_cast<int64_t>(std::floor(p.y() * inv)),
                     static_cast<int64_t>(std::floor(p.z() * inv)), static_cast<uint32_t>(i)});
  }
  std::sort(keyed.begin(), keyed.end(), [](const Keyed& a, const Keyed& b) {
    return std::tie(a.x, a.y, a.z, a.index) < std::tie(b.x, b.y, b.z, b.index);
  });
  auto sameVoxel = [](const Keyed& a, const Keyed& b) { return a.x == b.x && a.y == b.y && a.z == b.z; };
  size_t voxels = keyed.empty() ? 0 : 1;
  for (size_t i = 1; i < keyed.size(); ++i) voxels += !sameVoxel(keyed[i - 1], keyed[i]);
  Points out;
  out.reserve(voxels);  // exactly: callers keep these clouds for every keyframe
  for (size_t i = 0; i < keyed.size();) {
    size_t j = i;
    Vec3 sum = Vec3::Zero();
    while (j < keyed.size() && sameVoxel(keyed[j], keyed[i])) sum += finite[keyed[j++].index];
    out.push_back(sum / static_cast<double>(j - i));
    i = j;
  }
  return out;
}

}  // namespace livo::loop

namespace livo::loop {

void VoxelCentroids::add(const Vec3& p) {
  if (!p.allFinite()) return;
  if (voxel_ <= 0.0) {
    all_.push_back(p);
    return;
  }
  const double inv = 1.0 / voxel_;
  Sum& s = sums_[Key{static_cast<int64_t>(std::floor(p.x() * inv)), static_cast<int64_t>(std::floor(p.y() * inv)),
                     static_cast<int64_t>(std::floor(p.z() * inv))}];
  s.sum += p;
  ++s.count;
}

Points VoxelCentroids::centroids() const {
  if (voxel_ <= 0.0) return all_;
  std::vector<std::pair<Key, const Sum*>> keyed;
  keyed.reserve(sums_.size());
  for (const auto& [k, s] : sums_) keyed.emplace_back(k, &s);
  std::sort(keyed.begin(), keyed.end(),
            [](const auto& a, const auto& b) { return std::tie(a.first.x, a.first.y, a.first.z) < std::tie(b.first.x, b.first.y, b.first.z); });
  Points out;
  out.reserve(keyed.size());
  for (const auto& [k, s] : keyed) out.push_back(s->sum / static_cast<double>(s->count));
  return out;
}

}  // namespace livo::loop
