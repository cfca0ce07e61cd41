// Pose graph of keyframe poses: odometry edges between consecutive keyframes and loop edges,
// optimised with Ceres (SE(3) relative-pose residuals weighted by their information); the first
// keyframe is held fixed. The paper runs iSAM2 and updates only when a loop is added; here the
// optimisation runs on the same schedule, warm-started from the previous solution.
#pragma once

#include <cstdint>
#include <map>
#include <vector>

#include "livo/so3.hpp"

namespace livo::loop {

struct PoseGraphOptions {
  int max_iterations = 20;
  double function_tolerance = 1e-8;
  bool robust_loops = false;      // Cauchy loss on loop edges (off: loops are verified, and a
                                  // large first correction would be down-weighted away)
  double loop_loss_scale = 1.0;   // in units of the whitened residual
};

/// T_from_to measured with information (inverse covariance, [rotation; translation]).
struct PoseEdge {
  int64_t from = 0;
  int64_t to = 0;
  Pose3 T_from_to = Pose3::Identity();
  Mat6 information = Mat6::Identity();
  bool is_loop = false;
};

struct PoseGraphSummary {
  bool converged = false;
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
};

class PoseGraph {
 public:
  explicit PoseGraph(PoseGraphOptions options = {}) : options_(options) {}

  /// Adds (or replaces the estimate of) a node.
  void addNode(int64_t id, const Pose3& initial);
  bool hasNode(int64_t id) const { return poses_.count(id) > 0; }
  /// Throws std::invalid_argument if an end is unknown.
  void addEdge(const PoseEdge& edge);

  PoseGraphSummary optimize();

  const Pose3& pose(int64_t id) const;
  const std::map<int64_t, Pose3>& poses() const { return poses_; }
  const std::vector<PoseEdge>& edges() const { return edges_; }
  size_t numLoops() const;

 private:
  PoseGraphOptions options_;
  std::map<int64_t, Pose3> poses_;
  std::vector<PoseEdge> edges_;
};

/// The information of a relative edge from two absolute covariances (cov_to - cov_from,
/// eigenvalues clamped below at the floors), [rotation; translation].
Mat6 relativeInformation(const Mat6& cov_from, const Mat6& cov_to, double rotation_floor_rad, double translation_floor_m);

}  // namespace livo::loop
