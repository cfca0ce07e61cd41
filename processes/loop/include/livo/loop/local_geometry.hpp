// Per-point local geometry from a kd-tree neighbourhood: surface normals (for FPFH) and the
// plane-regularised covariances of GICP (Segal et al.; as Nano-GICP/fast_gicp compute them).
#pragma once

#include "livo/kdtree.hpp"
#include "livo/loop/point_types.hpp"

namespace livo::loop {

using PointTree = KdTree<Vec3>;

/// The shape of a point's neighbourhood within a radius: the eigen-decomposition of its scatter.
struct Neighbourhood {
  Vec3 normal = Vec3::Zero();       // unit, eigenvector of the smallest eigenvalue, towards the viewpoint
  Vec3 eigenvalues = Vec3::Zero();  // ascending
  int count = 0;                    // neighbours within the radius, the point included
};

/// Neighbourhoods of every point within `radius` (normals oriented towards `viewpoint`, the
/// sensor). A point with fewer than 3 neighbours gets a zero normal.
std::vector<Neighbourhood> analyseNeighbourhoods(const Points& points, const PointTree& tree, double radius,
                                                 const Vec3& viewpoint = Vec3::Zero());

/// GICP covariances from the k nearest neighbours, regularised plane-like: the eigenvectors of
/// the sample covariance with eigenvalues replaced by (1, 1, epsilon).
Covariances estimateCovariances(const Points& points, const PointTree& tree, int num_neighbors, double plane_epsilon);

}  // namespace livo::loop
