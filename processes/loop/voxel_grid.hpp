// Voxel-grid downsampling: one centroid per occupied voxel, in a deterministic order.
#pragma once

#include "point_types.hpp"

namespace livo::loop {

/// Drops non-finite points and replaces the points of each cubic voxel of edge `voxel_size` by
/// their centroid. Output is ordered by voxel index (independent of input order).
/// voxel_size <= 0 only removes non-finite points.
Points voxelDownsample(const Points& points, double voxel_size);

}  // namespace livo::loop
