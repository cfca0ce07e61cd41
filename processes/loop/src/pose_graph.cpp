#include "livo/loop/pose_graph.hpp"

#include <stdexcept>

#include <ceres/ceres.h>
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace livo::loop {

namespace {
// A pose as [p; q(x, y, z, w)] with tangent [dp; dtheta]: p + dp, q Exp(dtheta) (rotation on the
// right, translation in the world frame). The cost functions give their Jacobians directly in the
// tangent (columns 0-5 of a 7-column block, the last column zero), so the Plus Jacobian that Ceres
// chains them with is [I6; 0].
class PoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 6; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    Eigen::Map<const Vec3> p(x), dp(delta), dr(delta + 3);
    Eigen::Map<const Quat> q(x + 3);
    Eigen::Map<Vec3> p_out(x_plus_delta);
    Eigen::Map<Quat> q_out(x_plus_delta + 3);
    p_out = p + dp;
    q_out = (q * so3::ExpQuat(dr)).normalized();
    return true;
  }
  bool PlusJacobian(const double*, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    J.topRows<6>().setIdentity();
    return true;
  }
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    Eigen::Map<const Vec3> py(y), px(x);
    Eigen::Map<const Quat> qy(y + 3), qx(x + 3);
    Eigen::Map<Vec6> out(y_minus_x);
    out.head<3>() = py - px;
    out.tail<3>() = so3::Log(Quat(qx.conjugate() * qy));
    return true;
  }
  bool MinusJacobian(const double*, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    J.leftCols<6>().setIdentity();
    return true;
  }
};

// r = U [Log(R_m^T R_a^T R_b); R_a^T (p_b - p_a) - p_m] with U^T U the edge information.
class RelativePoseCost final : public ceres::SizedCostFunction<6, 7, 7> {
 public:
  RelativePoseCost(const Pose3& meas, const Mat6& sqrt_info)
      : q_meas_(Quat(meas.linear()).normalized()), p_meas_(meas.translation()), sqrt_info_(sqrt_info) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    Eigen::Map<const Vec3> pa(parameters[0]), pb(parameters[1]);
    Eigen::Map<const Quat> qa(parameters[0] + 3), qb(parameters[1] + 3);
    const Mat3 Ra = qa.toRotationMatrix();
    const Vec3 d = Ra.transpose() * (pb - pa);
    const Vec3 r_rot = so3::Log(Quat(q_meas_.conjugate() * qa.conjugate() * qb));
    Vec6 r;
    r << r_rot, d - p_meas_;
    Eigen::Map<Vec6> out(residuals);
    out = sqrt_info_ * r;
    if (!jacobians) return true;
    const Mat3 Jinv = so3::rightJacobianInverse(r_rot);
    using Jac = Eigen::Matrix<double, 6, 7, Eigen::RowMajor>;
    if (jacobians[0]) {
      Eigen::Matrix<double, 6, 6> J;  // columns [dp_a, dtheta_a]
      J.topLeftCorner<3, 3>().setZero();
      J.topRightCorner<3, 3>() = -Jinv * (qb.toRotationMatrix().transpose() * Ra);
      J.bottomLeftCorner<3, 3>() = -Ra.transpose();
      J.bottomRightCorner<3, 3>() = so3::hat(d);
      Eigen::Map<Jac> out(jacobians[0]);
      out.leftCols<6>() = sqrt_info_ * J;
      out.col(6).setZero();
    }
    if (jacobians[1]) {
      Eigen::Matrix<double, 6, 6> J;  // columns [dp_b, dtheta_b]
      J.topLeftCorner<3, 3>().setZero();
      J.topRightCorner<3, 3>() = Jinv;
      J.bottomLeftCorner<3, 3>() = Ra.transpose();
      J.bottomRightCorner<3, 3>().setZero();
      Eigen::Map<Jac> out(jacobians[1]);
      out.leftCols<6>() = sqrt_info_ * J;
      out.col(6).setZero();
    }
    return true;
  }

 private:
  Quat q_meas_;
  Vec3 p_meas_;
  Mat6 sqrt_info_;
};

// r = (R^T e_z - u) / sigma: the world's up axis in the node's frame against the prior's u. With
// R Exp(dtheta): Exp(-dtheta) v = v + hat(v) dtheta, so dr/dtheta = hat(R^T e_z) / sigma.
class GravityPriorCost final : public ceres::SizedCostFunction<3, 7> {
 public:
  GravityPriorCost(const Vec3& up_in_body, double sigma) : up_(up_in_body.normalized()), inv_sigma_(1.0 / sigma) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    Eigen::Map<const Quat> q(parameters[0] + 3);
    const Vec3 v = q.toRotationMatrix().transpose() * Vec3::UnitZ();
    Eigen::Map<Vec3> r(residuals);
    r = inv_sigma_ * (v - up_);
    if (jacobians && jacobians[0]) {
      Eigen::Map<Eigen::Matrix<double, 3, 7, Eigen::RowMajor>> J(jacobians[0]);
      J.setZero();
      J.block<3, 3>(0, 3) = inv_sigma_ * so3::hat(v);
    }
    return true;
  }

 private:
  Vec3 up_;
  double inv_sigma_;
};

Mat6 sqrtInformation(const Mat6& info) {
  Eigen::LLT<Mat6> llt(0.5 * (info + info.transpose()));
  if (llt.info() != Eigen::Success) return Mat6::Identity();
  return llt.matrixU();  // U^T U = info
}

PoseManifold& poseManifold() {
  static PoseManifold manifold;
  return manifold;
}

std::array<double, 7> toBlock(const Pose3& T) {
  std::array<double, 7> x;
  Eigen::Map<Vec3>(x.data()) = T.translation();
  Eigen::Map<Quat>(x.data() + 3) = Quat(T.linear()).normalized();
  return x;
}

Pose3 fromBlock(const std::array<double, 7>& x) {
  Pose3 T = Pose3::Identity();
  T.linear() = Eigen::Map<const Quat>(x.data() + 3).normalized().toRotationMatrix();
  T.translation() = Eigen::Map<const Vec3>(x.data());
  return T;
}
}  // namespace

PoseGraph::PoseGraph(PoseGraphOptions options) : options_(options) {}
PoseGraph::~PoseGraph() = default;
PoseGraph::PoseGraph(PoseGraph&&) noexcept = default;
PoseGraph& PoseGraph::operator=(PoseGraph&&) noexcept = default;

PoseGraph::PoseGraph(const PoseGraph& other)
    : options_(other.options_),
      poses_(other.poses_),
      blocks_(other.blocks_),
      edges_(other.edges_),
      loop_edges_(other.loop_edges_),
      held_fixed_(other.held_fixed_),
      gravity_priors_(other.gravity_priors_) {
  for (auto& [id, b] : blocks_) b.in_problem = false;
}

PoseGraph& PoseGraph::operator=(const PoseGraph& other) {
  if (this != &other) {
    PoseGraph copy(other);
    *this = std::move(copy);
  }
  return *this;
}

void PoseGraph::resetProblem() {
  problem_.reset();
  edges_in_problem_ = 0;
  priors_in_problem_ = 0;
  for (auto& [id, b] : blocks_) b.in_problem = false;
}

void PoseGraph::addNode(int64_t id, const Pose3& initial) {
  poses_[id] = initial;
  Block& b = blocks_[id];
  b.x = toBlock(initial);
}

void PoseGraph::addGravityPrior(int64_t id, const Vec3& up_in_body, double sigma) {
  if (!hasNode(id)) throw std::invalid_argument("pose graph gravity prior names an unknown node " + std::to_string(id));
  if (!(sigma > 0.0) || !up_in_body.allFinite() || up_in_body.norm() < 0.5)
    throw std::invalid_argument("pose graph gravity prior: sigma must be > 0 and the up axis a unit vector");
  gravity_priors_.push_back(GravityPrior{id, up_in_body, sigma});
}

bool PoseGraph::addEdge(const PoseEdge& edge) {
  if (!hasNode(edge.from) || !hasNode(edge.to))
    throw std::invalid_argument("pose graph edge " + std::to_string(edge.from) + " -> " + std::to_string(edge.to) +
                                " names an unknown node");
  if (edge.is_loop && options_.fuse_parallel_loops) {
    const auto [it, fresh] = loop_edges_.try_emplace({edge.from, edge.to}, edges_.size());
    if (!fresh) {
      // Both measure T_from_to with the residual [Log(R_m^T R); p - p_m]: around the first, the
      // second sits at m2 = [Log(R_1^T R_2); p_2] and the first at m1 = [0; p_1], and their sum of
      // squares is minimised at x = (L1 + L2)^-1 (L1 m1 + L2 m2) with information L1 + L2.
      PoseEdge& e = edges_[it->second];
      const Mat3 R1 = e.T_from_to.linear();
      Vec6 m1, m2;
      m1 << Vec3::Zero(), e.T_from_to.translation();
      m2 << so3::Log(Mat3(R1.transpose() * edge.T_from_to.linear())), edge.T_from_to.translation();
      const Mat6 L = e.information + edge.information;
      const Vec6 x = L.ldlt().solve(e.information * m1 + edge.information * m2);
      e.T_from_to.linear() = R1 * so3::Exp(Vec3(x.head<3>()));
      e.T_from_to.translation() = x.tail<3>();
      e.information = 0.5 * (L + L.transpose());
      if (it->second < edges_in_problem_) resetProblem();  // its residual is rebuilt at the next solve
      return false;
    }
  }
  edges_.push_back(edge);
  return true;
}

const Pose3& PoseGraph::pose(int64_t id) const {
  const auto it = poses_.find(id);
  if (it == poses_.end()) throw std::invalid_argument("pose graph: unknown node " + std::to_string(id));
  return it->second;
}

size_t PoseGraph::numLoops() const {
  size_t n = 0;
  for (const PoseEdge& e : edges_) n += e.is_loop;
  return n;
}

PoseGraphSummary PoseGraph::optimize() {
  PoseGraphSummary out;
  if (poses_.size() < 2 || edges_.empty()) return out;
  const int64_t first_id = blocks_.begin()->first;
  if (problem_ && first_id != fixed_id_) resetProblem();  // a node before the fixed one was added
  if (!problem_) {
    ceres::Problem::Options popts;
    popts.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_ = std::make_unique<ceres::Problem>(popts);
    edges_in_problem_ = 0;
    fixed_id_ = first_id;
  }
  ceres::Problem& problem = *problem_;
  auto ensureBlock = [&](int64_t id) {
    Block& b = blocks_.at(id);
    if (b.in_problem) return b.x.data();
    problem.AddParameterBlock(b.x.data(), 7, &poseManifold());
    if (id == first_id || held_fixed_.count(id)) problem.SetParameterBlockConstant(b.x.data());
    b.in_problem = true;
    return b.x.data();
  };
  for (; edges_in_problem_ < edges_.size(); ++edges_in_problem_) {
    const PoseEdge& e = edges_[edges_in_problem_];
    double* a = ensureBlock(e.from);
    double* b = ensureBlock(e.to);
    ceres::LossFunction* loss =
        (e.is_loop && options_.robust_loops) ? new ceres::CauchyLoss(options_.loop_loss_scale) : nullptr;
    problem.AddResidualBlock(new RelativePoseCost(e.T_from_to, sqrtInformation(e.information)), loss, a, b);
  }
  for (; priors_in_problem_ < gravity_priors_.size(); ++priors_in_problem_) {
    const GravityPrior& g = gravity_priors_[priors_in_problem_];
    problem.AddResidualBlock(new GravityPriorCost(g.up_in_body, g.sigma), nullptr, ensureBlock(g.id));
  }

  ceres::Solver::Options sopts;
  sopts.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  sopts.max_num_iterations = options_.max_iterations;
  sopts.function_tolerance = options_.function_tolerance;
  sopts.parameter_tolerance = options_.parameter_tolerance;
  sopts.num_threads = 1;
  // Warm-started, the problem is nearly linear: start Levenberg-Marquardt close to Gauss-Newton.
  // (Ceres' default radius damps the long, soft bending modes of a keyframe chain so much that
  // a solve took 14 iterations instead of 3.) A step that fails still shrinks the radius.
  sopts.initial_trust_region_radius = options_.initial_trust_region_radius;
  sopts.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(sopts, &problem, &summary);
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.iterations = static_cast<int>(summary.iterations.size());
  out.initial_cost = summary.initial_cost;
  out.final_cost = summary.final_cost;
  for (auto& [id, b] : blocks_)
    if (b.in_problem) poses_[id] = fromBlock(b.x);
  return out;
}

Mat6 relativeInformation(const Mat6& cov_from, const Mat6& cov_to, double rotation_floor_rad,
                         double translation_floor_m) {
  Mat6 d = cov_to - cov_from;
  d = (0.5 * (d + d.transpose())).eval();  // .eval(): the right side reads what the left writes
  if (!d.allFinite()) d.setZero();
  Eigen::SelfAdjointEigenSolver<Mat6> es(d);
  Vec6 ev = es.eigenvalues().cwiseMax(0.0);
  Mat6 cov = es.eigenvectors() * ev.asDiagonal() * es.eigenvectors().transpose();
  for (int i = 0; i < 3; ++i) cov(i, i) += rotation_floor_rad * rotation_floor_rad;
  for (int i = 3; i < 6; ++i) cov(i, i) += translation_floor_m * translation_floor_m;
  return cov.inverse();
}

}  // namespace livo::loop
