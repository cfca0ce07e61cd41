// Integer voxel coordinates packed into one 64-bit key: the one packing every voxel hash of the
// project uses (LIO map and scan downsampling, VIO point-patch map).
#pragma once

#include <cmath>
#include <cstdint>

#include "livo/so3.hpp"

namespace livo {

using VoxelKey = uint64_t;
/// No voxel packs to this (the top bit is never set): the empty slot of a hash table.
constexpr VoxelKey kNoVoxel = ~VoxelKey{0};

/// Packs three signed voxel coordinates (21 bits each, |c| < 2^20; x lowest) into a key.
inline VoxelKey packVoxel(int64_t x, int64_t y, int64_t z) {
  constexpr int64_t off = int64_t{1} << 20;
  constexpr uint64_t mask = (uint64_t{1} << 21) - 1;
  return (static_cast<uint64_t>(x + off) & mask) | ((static_cast<uint64_t>(y + off) & mask) << 21) |
         ((static_cast<uint64_t>(z + off) & mask) << 42);
}

/// The key of the voxel of side 1 / inv_size containing p (coordinates floor(p * inv_size)).
inline VoxelKey voxelKeyOf(const Vec3& p, double inv_size) {
  return packVoxel(static_cast<int64_t>(std::floor(p.x() * inv_size)),
                   static_cast<int64_t>(std::floor(p.y() * inv_size)),
                   static_cast<int64_t>(std::floor(p.z() * inv_size)));
}

}  // namespace livo
