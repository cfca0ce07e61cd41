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
  if (voxel_size <= 0.0) {
    Points finite;
    finite.reserve(points.size());
    for (const Vec3& p : points)
      if (p.allFinite()) finite.push_back(p);
    return finite;
  }
  // Group by voxel with an open-addressing hash, in point order (so each voxel's sum accumulates
  // in ascending point index, as a sort by (voxel, index) would), then sort only the voxels.
  struct Voxel {
    int64_t x, y, z;
    Vec3 sum;
    int64_t count;
  };
  std::vector<Voxel> voxels;
  size_t capacity = 16;
  while (capacity < 2 * points.size()) capacity *= 2;
  std::vector<uint32_t> slots(capacity, UINT32_MAX);  // index into voxels
  const size_t mask = capacity - 1;
  const double inv = 1.0 / voxel_size;
  for (const Vec3& p : points) {
    if (!p.allFinite()) continue;
    const int64_t x = static_cast<int64_t>(std::floor(p.x() * inv)), y = static_cast<int64_t>(std::floor(p.y() * inv)),
                  z = static_cast<int64_t>(std::floor(p.z() * inv));
    uint64_t h = (uint64_t(x) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(y) * 0xC2B2AE3D27D4EB4Full) ^
                 (uint64_t(z) * 0x165667B19E3779F9ull);
    h ^= h >> 29;
    size_t slot = static_cast<size_t>(h) & mask;
    while (true) {
      const uint32_t v = slots[slot];
      if (v == UINT32_MAX) {
        slots[slot] = static_cast<uint32_t>(voxels.size());
        voxels.push_back({x, y, z, Vec3::Zero() + p, 1});  // 0 + p, as a sum from zero (-0 becomes +0)
        break;
      }
      Voxel& vox = voxels[v];
      if (vox.x == x && vox.y == y && vox.z == z) {
        vox.sum += p;
        ++vox.count;
        break;
      }
      slot = (slot + 1) & mask;
    }
  }
  std::vector<uint32_t> order(voxels.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<uint32_t>(i);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return std::tie(voxels[a].x, voxels[a].y, voxels[a].z) < std::tie(voxels[b].x, voxels[b].y, voxels[b].z);
  });
  Points out;
  out.reserve(voxels.size());  // exactly: callers keep these clouds for every keyframe
  for (uint32_t v : order) out.push_back(voxels[v].sum / static_cast<double>(voxels[v].count));
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
  std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) {
    return std::tie(a.first.x, a.first.y, a.first.z) < std::tie(b.first.x, b.first.y, b.first.z);
  });
  Points out;
  out.reserve(keyed.size());
  for (const auto& [k, s] : keyed) out.push_back(s->sum / static_cast<double>(s->count));
  return out;
}

}  // namespace livo::loop
