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

/// floor(v) as an integer, |v| < 2^63. Inline arithmetic: at the build's baseline x86-64 (no SSE4.1
/// rounding instruction) std::floor is a libm call, and voxel hashing floors three times a point.
inline int64_t floorToInt(double v) {
  const int64_t i = static_cast<int64_t>(v);  // truncates towards zero
  return i - (static_cast<double>(i) > v ? 1 : 0);
}

/// The key of the voxel of side 1 / inv_size containing p (coordinates floor(p * inv_size)).
inline VoxelKey voxelKeyOf(const Vec3& p, double inv_size) {
  return packVoxel(floorToInt(p.x() * inv_size), floorToInt(p.y() * inv_size), floorToInt(p.z() * inv_size));
}

}  // namespace livo
