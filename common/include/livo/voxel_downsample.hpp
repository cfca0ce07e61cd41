// Voxel downsampling that keeps input points (no averaging): the first point of each voxel in
// input order. (The loop closure's centroidPerVoxel averages instead.)
#pragma once

#include <cstddef>
#include <vector>

#include "livo/so3.hpp"

namespace livo {

/// Indices of the first point falling in each voxel of the given size, in input order.
std::vector<size_t> firstPointPerVoxel(const std::vector<Vec3>& points, double voxel_size);
/// Same on a subset of indices.
std::vector<size_t> firstPointPerVoxel(const std::vector<Vec3>& points, const std::vector<size_t>& subset,
                                       double voxel_size);

}  // namespace livo
