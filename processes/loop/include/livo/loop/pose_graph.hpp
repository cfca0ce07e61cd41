// Pose graph of keyframe poses: odometry edges between consecutive keyframes and loop edges,
// optimised with Ceres (SE(3) relative-pose residuals weighted by their information, analytic
// Jacobians); the first keyframe is held fixed. The paper runs iSAM2 and updates only when a loop
// is added; here the optimisation runs on the same schedule and is incremental in the ways that
// matter for its cost: the Ceres problem persists between optimisations (new nodes and edges are
// appended, nothing is rebuilt) and every solve is warm-started from the previous solution, so
// a new loop costs a few Gauss-Newton steps on the whole graph. The optimum is the full solve's:
// no node is frozen or marginalised.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <utility>
#include <vector>

#include "livo/so3.hpp"

namespace ceres {
class Problem;
}

namespace livo::loop {

struct PoseGraphOptions {
  int max_iterations = 20;                    // per optimisation (a warm-started one needs 2-5)
  double function_tolerance = 1e-9;           // relative cost decrease at which a solve stops
  double parameter_tolerance = 1e-9;          // relative step size at which a solve stops
  double initial_trust_region_radius = 1e12;  // large: the first steps are Gauss-Newton steps
  bool robust_loops = false;                  // Cauchy loss on loop edges (off: loops are verified, and a
                                              // large first correction would be down-weighted away)
  double loop_loss_scale = 1.0;               // in units of the whitened residual
  /// A loop edge between the same two nodes, in the same direction, as an earlier loop edge is
  /// fused into it (information-weighted, to first order: the same optimum) instead of added:
  /// passes over a mapped route then add no edges once their node pairs are in the graph.
  bool fuse_parallel_loops = true;
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
  explicit PoseGraph(PoseGraphOptions options = {});
  ~PoseGraph();
  /// Copies the nodes and edges; the copy builds its own solver problem when it next optimises.
  PoseGraph(const PoseGraph& other);
  PoseGraph& operator=(const PoseGraph& other);
  PoseGraph(PoseGraph&&) noexcept;
  PoseGraph& operator=(PoseGraph&&) noexcept;

  /// Adds (or replaces the estimate of) a node.
  void addNode(int64_t id, const Pose3& initial);
  bool hasNode(int64_t id) const { return poses_.count(id) > 0; }
  /// Holds a node constant like the first one: the first keyframe of a graph segment (a segment
  /// starts after an odometry reset and has no edge to the ones before it).
  void holdFixed(int64_t id) { held_fixed_.insert(id); }
  /// Throws std::invalid_argument if an end is unknown. A loop edge parallel to an earlier one
  /// is fused into it (fuse_parallel_loops); returns false then.
  bool addEdge(const PoseEdge& edge);

  /// A prior on a node's roll and pitch: the world's up axis seen in the node's frame, R^T e_z,
  /// is `up_in_body` to within `sigma` (rad) per horizontal axis. An odometry that measures
  /// gravity knows its attitude to gravity absolutely; relative edges alone would let the graph
  /// trade it for whatever a loop asks.
  void addGravityPrior(int64_t id, const Vec3& up_in_body, double sigma);

  /// Minimises the whole graph from the current estimates (the previous solution for old nodes).
  PoseGraphSummary optimize();

  const Pose3& pose(int64_t id) const;
  const std::map<int64_t, Pose3>& poses() const { return poses_; }
  const std::vector<PoseEdge>& edges() const { return edges_; }
  size_t numLoops() const;

 private:
  // Ceres parameter block of a node: [p (3); q (x, y, z, w)]. std::map nodes do not move, so the
  // arrays stay valid as solver blocks while the graph grows.
  struct Block {
    std::array<double, 7> x{};
    bool in_problem = false;
  };
  void resetProblem();

  PoseGraphOptions options_;
  std::map<int64_t, Pose3> poses_;
  std::map<int64_t, Block> blocks_;
  std::vector<PoseEdge> edges_;
  std::map<std::pair<int64_t, int64_t>, size_t> loop_edges_;  // (from, to) -> index in edges_
  std::unique_ptr<ceres::Problem> problem_;
  size_t edges_in_problem_ = 0;
  int64_t fixed_id_ = 0;          // the node held constant in problem_
  std::set<int64_t> held_fixed_;  // first nodes of later segments (holdFixed)
  struct GravityPrior {
    int64_t id = 0;
    Vec3 up_in_body = Vec3::UnitZ();
    double sigma = 1.0;
  };
  std::vector<GravityPrior> gravity_priors_;
  size_t priors_in_problem_ = 0;
};

/// The information of a relative edge from two absolute covariances (cov_to - cov_from,
/// eigenvalues clamped below at the floors), [rotation; translation].
Mat6 relativeInformation(const Mat6& cov_from, const Mat6& cov_to, double rotation_floor_rad,
                         double translation_floor_m);

}  // namespace livo::loop
