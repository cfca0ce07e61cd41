// Marginalisation for the fixed-lag smoother: the factors that touch the states leaving the window
// are linearised at the current estimate and the leaving blocks eliminated (Schur complement);
// what they said about the blocks that stay becomes one linear prior on those (MarginalPrior),
// a factor like any other in the next windows (the scheme of OKVIS and VINS-Mono). Blocks are
// Euclidean or quaternions on RightQuaternionManifold.
#pragma once

#include <map>
#include <memory>
#include <set>
#include <vector>

#include <ceres/ceres.h>
#include <Eigen/Core>

#include "livo/so3.hpp"

namespace livo {

/// A linear prior r(x) = r0 + J (x [-] x0) on parameter blocks, [-] per block (Euclidean
/// difference; Log(q0^-1 q) for quaternions).
struct MarginalPrior {
  std::vector<double*> blocks;
  std::vector<int> sizes;  // ambient
  std::vector<bool> quaternion;
  std::vector<Eigen::VectorXd> x0;
  Eigen::MatrixXd J;  // rows: rank, columns: sum of tangent sizes
  Eigen::VectorXd r0;
  int tangentSize() const { return static_cast<int>(J.cols()); }
};

/// How a block changes when the world frame moves rigidly by T = (R, t) (a loop correction).
enum class WorldMotion {
  kNone,       // body-frame quantities (biases)
  kRotation,   // an orientation W_R_I (quaternion): R q; its right-perturbation tangent is body-frame
  kPoint,      // a world point (a position): R p + t
  kDirection,  // a world vector (a velocity, a plane landmark's c): R v
};

/// The prior on the blocks moved by T: r'(x') = r(x) for every x, x' being x moved
/// (motion[b] for blocks[b]). The linearisation points move with their blocks; the Jacobian
/// columns of points and directions turn by R^T, as their tangent (x - x0) is a world-frame
/// difference; quaternion tangents (Log(q0^-1 q)) and body-frame blocks stay. The blocks keep their
/// pointers (the state moves in place). Throws std::invalid_argument for a motion that does not fit
/// its block (a rotation on a Euclidean block, a point or direction on a block not of size 3).
MarginalPrior movedPrior(const MarginalPrior& prior, const std::vector<WorldMotion>& motion, const Pose3& T);

class MarginalPriorFactor : public ceres::CostFunction {
 public:
  explicit MarginalPriorFactor(std::shared_ptr<const MarginalPrior> prior);
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;
  const MarginalPrior& prior() const { return *prior_; }

 private:
  std::shared_ptr<const MarginalPrior> prior_;
};

class Marginalizer {
 public:
  /// Marks a block as a quaternion (x y z w, tangent size 3); any other block is Euclidean.
  void setQuaternion(const double* block) { quaternions_.insert(block); }
  /// A factor touching a block to be eliminated; `cost` (and `loss`, which may be null) are not
  /// owned and must live until marginalize() returns. Blocks in the cost function's order. A robust
  /// loss is linearised as its weight at the current residual (its first derivative).
  void addFactor(const ceres::CostFunction* cost, std::vector<double*> blocks,
                 const ceres::LossFunction* loss = nullptr);
  /// Linearises every factor at the blocks' current values and eliminates `drop`. Null if no
  /// block stays (nothing to keep). Eigenvalues below `eps` (relative to the largest) are dropped.
  std::shared_ptr<MarginalPrior> marginalize(const std::set<const double*>& drop, double eps = 1e-10) const;
  /// The information on `keep` (tangent coordinates, blocks in this order) once every other block
  /// the factors touch is eliminated (Schur complement), linearised as marginalize() does. By a
  /// Cholesky factorisation of the eliminated blocks' information, far cheaper than marginalize()'s
  /// eigen-decompositions; false if that is not positive definite (marginalize() then handles the
  /// rank deficiency) or a kept block is touched by no factor.
  bool marginalInformation(const std::vector<const double*>& keep, Eigen::MatrixXd* info) const;

 private:
  struct Factor {
    const ceres::CostFunction* cost;
    std::vector<double*> blocks;
    const ceres::LossFunction* loss;
  };
  /// Every block the factors touch, those in `first` first, each group in first-seen order; their
  /// ambient sizes into `ambient`.
  std::vector<double*> blockOrder(const std::set<const double*>& first, std::map<const double*, int>* ambient) const;
  /// H = J^T J and g = J^T r of every factor at the blocks' current values, the blocks' tangent
  /// coordinates in `order`.
  void linearize(const std::vector<double*>& order, std::map<const double*, int>* ambient, Eigen::MatrixXd* H,
                 Eigen::VectorXd* g) const;

  std::vector<Factor> factors_;
  std::set<const double*> quaternions_;
};

}  // namespace livo
