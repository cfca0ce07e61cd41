// A voxel's index in a block of 2^Bits voxels per axis as its Morton code (x in the lowest bit of
// each triple, as octomap's child index), and the index moved by one voxel along one axis without
// decoding it: a ray walk steps one axis at a time, so its voxels are addressed by one add on that
// axis's bit lanes ("dilated integer" arithmetic) instead of re-interleaving the key each voxel.
// tests/octomap/test_octomap_core.cpp checks the moves against the interleaved keys.
#pragma once

namespace livo::octomap::morton {

/// The bits of axis A (0 x, 1 y, 2 z) in an index of Bits bits per axis.
template <int A, int Bits>
constexpr unsigned lanes() {
  unsigned m = 0;
  for (int j = 0; j < Bits; ++j) m |= 1u << (3 * j + A);
  return m;
}

/// The index of the voxel (x, y, z), each below 2^Bits.
template <int Bits>
constexpr unsigned index(unsigned x, unsigned y, unsigned z) {
  unsigned i = 0;
  for (int j = 0; j < Bits; ++j)
    i |= (((x >> j) & 1u) << (3 * j)) | (((y >> j) & 1u) << (3 * j + 1)) | (((z >> j) & 1u) << (3 * j + 2));
  return i;
}

/// True when the voxel is the block's last (first) along axis A: a step up (down) leaves the block.
template <int A, int Bits>
constexpr bool atTop(unsigned i) {
  return (i & lanes<A, Bits>()) == lanes<A, Bits>();
}
template <int A, int Bits>
constexpr bool atBottom(unsigned i) {
  return (i & lanes<A, Bits>()) == 0;
}

/// One voxel up (down) along axis A, wrapping around within the block: setting the other axes'
/// bits makes the carry (borrow) run through them to the next lane of A.
template <int A, int Bits>
constexpr unsigned up(unsigned i) {
  constexpr unsigned m = lanes<A, Bits>();
  return (((i | ~m) + 1u) & m) | (i & ~m);
}
template <int A, int Bits>
constexpr unsigned down(unsigned i) {
  constexpr unsigned m = lanes<A, Bits>();
  return (((i & m) - 1u) & m) | (i & ~m);
}

}  // namespace livo::octomap::morton
