// The coarse stage's per-keyframe input, computed once and cached: a voxel-downsampled cloud and
// FPFH features of its non-horizontal points (ground and roofs match everywhere, so they are
// left out of matching as Quatro does with ground segmentation).
#pragma once

#include "fpfh.hpp"
#include "point_types.hpp"

namespace livo::loop {

struct CoarseFeatureOptions {
  double voxel_size = 1.0;          // m
  double normal_radius = 2.0;       // m
  double feature_radius = 2.5;      // m
  double max_normal_z = 0.9;        // points with |n_z| above this are not matched
};

struct CoarseFeatures {
  Points points;      // matched points (non-horizontal), body frame of the keyframe
  Features features;  // one per point
};

/// From a gravity-aligned cloud (z up), so that "horizontal" means ground-like.
CoarseFeatures computeCoarseFeatures(const Points& cloud, const CoarseFeatureOptions& options);

}  // namespace livo::loop
