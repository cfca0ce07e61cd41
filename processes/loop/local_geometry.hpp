// Per-point local geometry from a kd-tree neighbourhood: surface normals (for FPFH) and the
// plane-regularised covariances of GICP (Segal et al.; as Nano-GICP/fast_gicp compute them).
#pragma once

#include "kdtree.hpp"
#include "point_types.hpp"

namespace livo::loop {

using PointTree = KdTree<Vec3>;

struct LocalGeometryOptions {
  int num_neighbors = 10;         // k of the kNN neighbourhood of the covariances
  double normal_radius = 1.0;     // m, neighbourhood of the normals (FPFH)
  double plane_epsilon = 1e-3;    // GICP: covariance eigenvalues become (1, 1, epsilon)
};

/// Unit normals from the neighbours within `radius`, oriented towards `viewpoint` (the sensor).
/// A point with fewer than 3 neighbours gets a zero normal.
Points estimateNormals(const Points& points, const PointTree& tree, double radius,
                       const Vec3& viewpoint = Vec3::Zero());

/// GICP covariances from the k nearest neighbours, regularised plane-like: the eigenvectors of
/// the sample covariance with eigenvalues replaced by (1, 1, epsilon).
Covariances estimateCovariances(const Points& points, const PointTree& tree, int num_neighbors,
                                double plane_epsilon);

}  // namespace livo::loop
