#include "coarse_features.hpp"

#include <cmath>

#include "voxel_grid.hpp"

namespace livo::loop {

CoarseFeatures computeCoarseFeatures(const Points& cloud, const CoarseFeatureOptions& options) {
  const Points points = voxelDownsample(cloud, options.voxel_size);
  CoarseFeatures out;
  if (points.empty()) return out;
  const PointTree tree(points);
  const Points normals = estimateNormals(points, tree, options.normal_radius);
  const Features all = computeFpfh(points, normals, tree, options.feature_radius);
  for (size_t i = 0; i < points.size(); ++i) {
    if (normals[i].isZero() || std::abs(normals[i].z()) > options.max_normal_z || all[i].isZero()) continue;
    out.points.push_back(points[i]);
    out.features.push_back(all[i]);
  }
  return out;
}

}  // namespace livo::loop
