// The coarse stage's per-keyframe input, computed once and cached: ISS keypoints of a
// voxel-downsampled cloud, and their FPFH features quantised to byte descriptors. Near-horizontal
// surfaces (ground, roofs) match everywhere, so points whose normal is close to vertical are not
// keypoints, as Quatro leaves out the ground.
#pragma once

#include "livo/loop/feature_matching.hpp"
#include "livo/loop/fpfh.hpp"
#include "livo/loop/keypoints.hpp"
#include "livo/loop/point_types.hpp"

namespace livo::loop {

struct CoarseFeatureOptions {
  double voxel_size = 0.6;          // m
  double normal_radius = 1.0;       // m, normals and ISS saliency
  double feature_radius = 2.5;      // m, FPFH
  double max_normal_z = 0.9;        // points with |n_z| above this are not keypoints
  int max_keypoints = 1500;         // the most salient are kept (bounds the matching time)
  IssOptions keypoints;
};

struct CoarseFeatures {
  Points points;            // keypoints, in the frame of the cloud
  Descriptors descriptors;  // one per keypoint
  size_t size() const { return points.size(); }
};

/// From a gravity-aligned cloud (z up), so that "horizontal" means ground-like; the sensor at the
/// origin (normals point towards it).
CoarseFeatures computeCoarseFeatures(const Points& cloud, const CoarseFeatureOptions& options);

}  // namespace livo::loop
