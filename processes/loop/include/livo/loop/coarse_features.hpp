// The coarse stage's per-keyframe input, computed once and cached: ISS keypoints of a
// voxel-downsampled cloud, and their FPFH features quantised to byte descriptors. Near-horizontal
// surfaces (ground, roofs) match everywhere, so points whose normal is close to vertical are not
// keypoints, as Quatro leaves out the ground.
//
// In two stages, because whether a keyframe has any coarse features at all is needed for every
// keyframe that may be a registration's source or target, its descriptors only when one is
// attempted: detectCoarseKeypoints (voxels, normals, ISS) and describeCoarseKeypoints (FPFH, about
// half the time). anyKeypointDescribable tells from the first stage, exactly and usually from a
// single pair of points, whether the second will keep any keypoint.
#pragma once

#include <memory>
#include <vector>

#include "livo/loop/feature_matching.hpp"
#include "livo/loop/fpfh.hpp"
#include "livo/loop/keypoints.hpp"
#include "livo/loop/point_types.hpp"

namespace livo::loop {

struct CoarseFeatureOptions {
  double voxel_size = 0.6;      // m
  double normal_radius = 1.0;   // m, normals and ISS saliency
  double feature_radius = 2.5;  // m, FPFH
  double max_normal_z = 0.9;    // points with |n_z| above this are not keypoints
  int max_keypoints = 1500;     // the most salient are kept (bounds the matching time)
  IssOptions keypoints;
};

struct CoarseFeatures {
  Points points;            // keypoints, in the frame of the cloud
  Descriptors descriptors;  // one per keypoint
  size_t size() const { return points.size(); }
};

/// The first stage: the voxel centroids with their normals and kd-tree, and the keypoints among
/// them. The points live on the heap so the tree's reference survives moves and copies.
struct CoarseKeypoints {
  std::shared_ptr<const Points> points;   // voxel centroids (null if there are none)
  Points normals;                         // per point (zero: fewer than 3 neighbours)
  std::shared_ptr<const PointTree> tree;  // over *points (null if there are none)
  std::vector<int> keys;                  // indices into *points, most salient first, at most max_keypoints
};

/// From a gravity-aligned cloud (z up), so that "horizontal" means ground-like; the sensor at the
/// origin (normals point towards it).
CoarseKeypoints detectCoarseKeypoints(const Points& cloud, const CoarseFeatureOptions& options);

/// The second stage: the keypoints with a non-zero FPFH (the others have no valid pair of points
/// within feature_radius and are left out), with their descriptors.
CoarseFeatures describeCoarseKeypoints(const CoarseKeypoints& keypoints, const CoarseFeatureOptions& options);

/// Exactly !describeCoarseKeypoints(keypoints, options).points.empty(), usually for the price of a
/// radius search or two (see anyNonZeroFpfh).
bool anyKeypointDescribable(const CoarseKeypoints& keypoints, const CoarseFeatureOptions& options);

/// Both stages.
CoarseFeatures computeCoarseFeatures(const Points& cloud, const CoarseFeatureOptions& options);

}  // namespace livo::loop
