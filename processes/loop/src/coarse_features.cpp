#include "livo/loop/coarse_features.hpp"

#include <cmath>

#include "livo/loop/voxel_grid.hpp"

namespace livo::loop {

CoarseKeypoints detectCoarseKeypoints(const Points& cloud, const CoarseFeatureOptions& options) {
  CoarseKeypoints out;
  auto points = std::make_shared<const Points>(centroidPerVoxel(cloud, options.voxel_size));
  if (points->empty()) return out;
  out.points = points;
  out.tree = std::make_shared<const PointTree>(*points);
  const std::vector<Neighbourhood> geometry = analyseNeighbourhoods(*points, *out.tree, options.normal_radius);
  std::vector<char> eligible(points->size(), 0);
  out.normals.resize(points->size());
  for (size_t i = 0; i < points->size(); ++i) {
    out.normals[i] = geometry[i].normal;
    eligible[i] = !out.normals[i].isZero() && std::abs(out.normals[i].z()) <= options.max_normal_z;
  }
  out.keys = issKeypoints(*points, geometry, *out.tree, options.keypoints, eligible);
  if (options.max_keypoints > 0 && out.keys.size() > static_cast<size_t>(options.max_keypoints))
    out.keys.resize(options.max_keypoints);
  return out;
}

CoarseFeatures describeCoarseKeypoints(const CoarseKeypoints& keypoints, const CoarseFeatureOptions& options) {
  CoarseFeatures out;
  if (keypoints.keys.empty()) return out;
  const Points& points = *keypoints.points;
  const Features features =
      computeFpfh(points, keypoints.normals, *keypoints.tree, options.feature_radius, keypoints.keys);
  out.points.reserve(keypoints.keys.size());
  out.descriptors.reserve(keypoints.keys.size());
  for (size_t k = 0; k < keypoints.keys.size(); ++k) {
    if (features[k].isZero()) continue;
    out.points.push_back(points[keypoints.keys[k]]);
    out.descriptors.push_back(quantise(features[k]));
  }
  return out;
}

bool anyKeypointDescribable(const CoarseKeypoints& keypoints, const CoarseFeatureOptions& options) {
  // describeCoarseKeypoints keeps a keypoint iff its FPFH is non-zero: anyNonZeroFpfh's question
  if (keypoints.keys.empty()) return false;
  return anyNonZeroFpfh(*keypoints.points, keypoints.normals, *keypoints.tree, options.feature_radius, keypoints.keys);
}

CoarseFeatures computeCoarseFeatures(const Points& cloud, const CoarseFeatureOptions& options) {
  return describeCoarseKeypoints(detectCoarseKeypoints(cloud, options), options);
}

}  // namespace livo::loop
