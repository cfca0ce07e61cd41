#include "livo/voxel_downsample.hpp"

#include <algorithm>

#include "livo/flat_key_index.hpp"
#include "livo/voxel_key.hpp"

namespace livo {

namespace {

// The points at indexOf(0), ..., indexOf(n - 1), in that order.
template <typename IndexOf>
std::vector<size_t> firstPointPerVoxelOf(const std::vector<Vec3>& points, size_t n, IndexOf indexOf,
                                         double voxel_size) {
  const double inv = 1.0 / voxel_size;
  // Sized for the voxels, not the points: a dense sweep has tens of points per voxel, and a table
  // for all of them (8 MB for a 64-beam sweep) costs more to clear and misses the cache more than
  // the few doublings it grows by.
  FlatKeyIndex seen(std::min<size_t>(n, 1024));
  std::vector<size_t> out;
  out.reserve(n / 4 + 16);
  VoxelKey last = kNoVoxel;  // a sweep's consecutive points often share a voxel: no lookup then
  for (size_t i = 0; i < n; ++i) {
    const size_t j = indexOf(i);
    const VoxelKey key = voxelKeyOf(points[j], inv);
    if (key == last) continue;
    last = key;
    const int32_t next = static_cast<int32_t>(out.size());
    if (seen.insert(key, next) == next) out.push_back(j);
  }
  return out;
}

}  // namespace

std::vector<size_t> firstPointPerVoxel(const std::vector<Vec3>& points, const std::vector<size_t>& subset,
                                       double voxel_size) {
  return firstPointPerVoxelOf(
      points, subset.size(), [&](size_t i) { return subset[i]; }, voxel_size);
}

std::vector<size_t> firstPointPerVoxel(const std::vector<Vec3>& points, double voxel_size) {
  return firstPointPerVoxelOf(
      points, points.size(), [](size_t i) { return i; }, voxel_size);
}

}  // namespace livo
