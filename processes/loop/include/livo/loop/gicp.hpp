// Nano-GICP (Koide et al.'s fast_gicp, as used by FAST-LIO-SAM-QN): generalized ICP with
// per-point covariances from kNN neighbourhoods, Gauss-Newton on SE(3).
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "livo/loop/local_geometry.hpp"
#include "livo/loop/point_types.hpp"

namespace livo::loop {

/// A symmetric 3x3 matrix kept as six floats (xx, xy, xz, yy, yz, zz): a third of a Mat3. Every
/// keyframe keeps one per fine point, so this is most of the loop closer's memory.
class CompactCovariance {
 public:
  explicit CompactCovariance(const Mat3& m = Mat3::Identity());
  Mat3 matrix() const;

 private:
  std::array<float, 6> c_;
};

/// A cloud ready for GICP: points, their covariances and a kd-tree over the points.
/// The points live on the heap so the tree's reference survives moves and copies.
struct GicpCloud {
  std::shared_ptr<const Points> cloud;
  std::vector<CompactCovariance> covariances;
  std::shared_ptr<const PointTree> tree;
  const Points& points() const { return *cloud; }
  size_t size() const { return cloud ? cloud->size() : 0; }
  /// Computes covariances and the tree for `points` (moved in).
  static GicpCloud build(Points points, int num_neighbors = 10, double plane_epsilon = 1e-3);
};

struct GicpOptions {
  double max_correspondence_distance = 1.0;  // m
  int max_iterations = 30;
  double rotation_epsilon = 2e-4;     // rad: converged when the update is smaller
  double translation_epsilon = 1e-4;  // m
  double overlap_distance = 0.5;      // m, a source point "overlaps" within this
  int max_source_points = 6000;       // source thinned evenly to at most this many (0: all);
                                      // the target keeps every point
};

struct GicpResult {
  Pose3 T_target_source = Pose3::Identity();
  bool converged = false;
  int iterations = 0;
  double fitness = 0.0;  // mean squared distance of correspondences within max distance, m^2
  double overlap = 0.0;  // fraction of (used) source points with a target point within overlap_distance
  int num_correspondences = 0;
  /// Gauss-Newton Hessian of the GICP cost at the solution, [rotation; translation], for a left
  /// perturbation in the target frame (T' = [Exp(dr), dt] T). Its scale is that of the regularised
  /// covariances (1 m^2 in the plane, plane_epsilon along the normal), not of the sensor, and its
  /// in-plane terms constrain directions the surfaces do not (a corridor along its axis): it steers
  /// the solver, it is no covariance (see plane_information).
  Mat6 information = Mat6::Zero();
  /// Point-to-plane information at the solution, same perturbation and order: sum of J^T n n^T J
  /// over the correspondences (n the normal of the pair's summed covariance) divided by
  /// plane_residual_variance. Only the normal components constrain the pose; their noise comes
  /// from the residuals themselves (sensor noise, surface roughness, sampling), so this is an
  /// inverse covariance to the extent the correspondences are independent and the surfaces planar.
  Mat6 plane_information = Mat6::Zero();
  double plane_residual_variance = 0.0;  // m^2: sum of (n . e)^2 over (correspondences - 6)
  int plane_correspondences = 0;
  double min_translation_eigenvalue = 0.0;  // of the Hessian's translation block per correspondence
  /// Smallest over largest eigenvalue of that block: near 0 when one direction is constrained only
  /// by the weak in-plane terms (a corridor along its axis), whatever the point count.
  double translation_eigenvalue_ratio = 0.0;
};

GicpResult gicpRegister(const GicpCloud& source, const GicpCloud& target, const Pose3& initial,
                        const GicpOptions& options);

}  // namespace livo::loop
