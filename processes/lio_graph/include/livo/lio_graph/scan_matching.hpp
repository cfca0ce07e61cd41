// Scan-to-local-map matching (LIO-SAM's mapOptimization, the LiDAR odometry factor's measurement):
// the sweep's edge points against lines and its surface points against planes fitted to their
// nearest neighbours in the local map, Gauss-Newton on the pose from the IMU prediction. Directions
// the geometry does not constrain (the eigenvalues of J^T J below a threshold: a corridor, a bridge
// deck) are left at the prediction and reported, and the information of the result says so: the
// graph then takes those directions from the IMU and the wheels.
#pragma once

#include <memory>
#include <vector>

#include "livo/kdtree.hpp"
#include "livo/lio_graph/feature_extraction.hpp"
#include "livo/so3.hpp"

namespace livo::lio_graph {

struct ScanMatchingOptions {
  // A plane is accepted as livo-lio accepts one (livo/plane.hpp's fitPlane): its neighbours within
  // max_neighbour_distance, every one within max_plane_distance of it, and not nearly collinear (the
  // scatter's second eigenvalue at least min_planarity times the largest; 0: no such test). LIO-SAM's
  // 1 m, 0.2 m and no collinearity test let a corner, or a few points of one far ring, stand for a
  // plane whose normal nothing fixed: with them the held-out bridge_deck and campus_loop runs had
  // 2.7x and 1.9x the ATE (README, "Against livo-lio"). The price: in a map of one sweep the floor
  // is single-ring arcs, which are refused, and the height rests on fewer points.
  int neighbours = 5;                   // per line and per plane
  double max_neighbour_distance = 1.5;  // m, the farthest of them
  double max_plane_distance = 0.03;     // m
  double min_planarity = 0.02;
  double min_line_ratio = 3.0;  // largest / second eigenvalue of the neighbours for a line
  int max_iterations = 30;
  double converged_rotation = 1e-3;     // rad, update norm
  double converged_translation = 1e-3;  // m
  double degenerate_eigenvalue = 50.0;  // of the weighted J^T J (one residual per point)
  int min_residuals = 50;
};

/// The local map: edge and surface points in the world frame with a kd-tree each. It keeps the
/// points the trees refer to, so it is neither copied nor moved; rebuild() replaces its content.
class LocalMap {
 public:
  LocalMap() = default;
  LocalMap(const LocalMap&) = delete;
  LocalMap& operator=(const LocalMap&) = delete;

  void rebuild(std::vector<Vec3> edges, std::vector<Vec3> surfaces);
  const std::vector<Vec3>& edges() const { return edges_; }
  const std::vector<Vec3>& surfaces() const { return surfaces_; }
  const KdTree<Vec3>* edgeTree() const { return edge_tree_.get(); }
  const KdTree<Vec3>* surfaceTree() const { return surface_tree_.get(); }
  bool empty() const { return surfaces_.empty() && edges_.empty(); }

 private:
  std::vector<Vec3> edges_, surfaces_;
  std::unique_ptr<KdTree<Vec3>> edge_tree_, surface_tree_;
};

struct ScanMatchResult {
  bool valid = false;  // enough residuals and a finite pose
  Pose3 T_W_I = Pose3::Identity();
  /// J^T J of the last iterate in the coordinates [dtheta (right, body), dt (world)] of
  /// T = (R Exp(dtheta), t + dt), one unit-weight residual per point: the information of the pose
  /// up to the point noise (the graph scales it).
  Mat6 hessian = Mat6::Zero();
  Vec6 eigenvalues = Vec6::Zero();  // of `hessian`, ascending
  Vec6 weakest = Vec6::Zero();      // the eigenvector of the smallest
  bool degenerate = false;          // some eigenvalue below degenerate_eigenvalue
  int edge_residuals = 0;
  int surface_residuals = 0;
  int iterations = 0;
  bool converged = false;
};

/// Matches the sweep's features (body frame I, deskewed to the sweep end) against the map from
/// `initial` (W_T_I).
ScanMatchResult matchScan(const LocalMap& map, const ScanFeatures& features, const Pose3& initial,
                          const ScanMatchingOptions& options);

}  // namespace livo::lio_graph
