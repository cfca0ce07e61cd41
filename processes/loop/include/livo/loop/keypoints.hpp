// Intrinsic Shape Signature keypoints (Zhong, ICCV workshops 2009): points whose neighbourhood
// scatter has three distinct eigenvalues (not a plane, a line or a symmetric blob) and whose
// smallest eigenvalue, the saliency, is the largest within a radius: corners, object edges,
// trunks. Unlike voxel centroids they sit on the same physical spots in two scans, so their FPFH
// features match; with fewer of them, exhaustive matching stays cheap.
#pragma once

#include <vector>

#include "livo/loop/local_geometry.hpp"

namespace livo::loop {

struct IssOptions {
  double gamma21 = 0.975;      // keep lambda2 / lambda1 below this (lambda1 >= lambda2 >= lambda3)
  double gamma32 = 0.975;      // keep lambda3 / lambda2 below this
  double min_variation = 0.0;  // lambda3 / (lambda1 + lambda2 + lambda3): 0 keeps noise on planes
  int min_neighbours = 6;
  double nms_radius = 0.6;  // m: a keypoint has the largest saliency within this radius
};

/// Indices of the keypoints among `points` (with their neighbourhoods from analyseNeighbourhoods),
/// most salient first (lower index first on ties). `eligible` (if not empty) excludes points.
std::vector<int> issKeypoints(const Points& points, const std::vector<Neighbourhood>& geometry, const PointTree& tree,
                              const IssOptions& options, const std::vector<char>& eligible = {});

}  // namespace livo::loop
