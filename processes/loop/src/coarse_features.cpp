#include "livo/loop/coarse_features.hpp"

#include <cmath>

#include "livo/loop/voxel_grid.hpp"

namespace livo::loop {

CoarseFeatures computeCoarseFeatures(const Points& cloud, const CoarseFeatureOptions& options) {
  const Points points = centroidPerVoxel(cloud, options.voxel_size);
  CoarseFeatures out;
  if (points.empty()) return out;
  const PointTree tree(points);
  const std::vector<Neighbourhood> geometry = analyseNeighbourhoods(points, tree, options.normal_radius);
  std::vector<char> eligible(points.size(), 0);
  Points normals(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    normals[i] = geometry[i].normal;
    eligible[i] = !normals[i].isZero() && std::abs(normals[i].z()) <= options.max_normal_z;
  }
  std::vector<int> keys = issKeypoints(points, geometry, tree, options.keypoints, eligible);
  if (options.max_keypoints > 0 && keys.size() > static_cast<size_t>(options.max_keypoints))
    keys.resize(options.max_keypoints);
  const Features features = computeFpfh(points, normals, tree, options.feature_radius, keys);
  out.points.reserve(keys.size());
  out.descriptors.reserve(keys.size());
  for (size_t k = 0; k < keys.size(); ++k) {
    if (features[k].isZero()) continue;
    out.points.push_back(points[keys[k]]);
    out.descriptors.push_back(quantise(features[k]));
  }
  return out;
}

}  // namespace livo::loop
