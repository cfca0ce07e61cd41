#include "pose_graph.hpp"

#include <stdexcept>

#include <ceres/ceres.h>
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace livo::loop {

namespace {
// r = sqrt_info * [2 vec(q_meas^-1 q_from^-1 q_to); R_from^T (p_to - p_from) - p_meas].
struct RelativePoseError {
  RelativePoseError(const Pose3& meas, const Mat6& sqrt_info)
      : q_meas(Quat(meas.linear()).normalized()), p_meas(meas.translation()), sqrt_info(sqrt_info) {}

  template <class T>
  bool operator()(const T* p_a, const T* q_a, const T* p_b, const T* q_b, T* residual) const {
    Eigen::Map<const Eigen::Matrix<T, 3, 1>> pa(p_a), pb(p_b);
    Eigen::Map<const Eigen::Quaternion<T>> qa(q_a), qb(q_b);
    const Eigen::Quaternion<T> q_ab = qa.conjugate() * qb;
    const Eigen::Matrix<T, 3, 1> p_ab = qa.conjugate() * (pb - pa);
    const Eigen::Quaternion<T> dq = q_meas.template cast<T>().conjugate() * q_ab;
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(residual);
    r.template head<3>() = T(2.0) * dq.vec();
    r.template tail<3>() = p_ab - p_meas.template cast<T>();
    r.applyOnTheLeft(sqrt_info.template cast<T>());
    return true;
  }

  Quat q_meas;
  Vec3 p_meas;
  Mat6 sqrt_info;
};

Mat6 sqrtInformation(const Mat6& info) {
  Eigen::LLT<Mat6> llt(0.5 * (info + info.transpose()));
  if (llt.info() != Eigen::Success) return Mat6::Identity();
  return llt.matrixU();  // U^T U = info
}
}  // namespace

void PoseGraph::addNode(int64_t id, const Pose3& initial) { poses_[id] = initial; }

void PoseGraph::addEdge(const PoseEdge& edge) {
  if (!hasNode(edge.from) || !hasNode(edge.to))
    throw std::invalid_argument("pose graph edge " + std::to_string(edge.from) + " -> " + std::to_string(edge.to) +
                                " names an unknown node");
  edges_.push_back(edge);
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
  struct Block {
    Eigen::Vector3d p;
    Eigen::Quaterniond q;
  };
  std::map<int64_t, Block> blocks;
  for (const auto& [id, T] : poses_) blocks[id] = {T.translation(), Quat(T.linear()).normalized()};

  ceres::Problem::Options popts;
  popts.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(popts);
  ceres::EigenQuaternionManifold quaternion_manifold;
  for (const PoseEdge& e : edges_) {
    Block& a = blocks.at(e.from);
    Block& b = blocks.at(e.to);
    auto* cost = new ceres::AutoDiffCostFunction<RelativePoseError, 6, 3, 4, 3, 4>(
        new RelativePoseError(e.T_from_to, sqrtInformation(e.information)));
    ceres::LossFunction* loss = (e.is_loop && options_.robust_loops) ? new ceres::CauchyLoss(options_.loop_loss_scale) : nullptr;
    problem.AddResidualBlock(cost, loss, a.p.data(), a.q.coeffs().data(), b.p.data(), b.q.coeffs().data());
  }
  for (auto& [id, b] : blocks)
    if (problem.HasParameterBlock(b.q.coeffs().data())) problem.SetManifold(b.q.coeffs().data(), &quaternion_manifold);
  Block& first = blocks.begin()->second;
  if (problem.HasParameterBlock(first.p.data())) {
    problem.SetParameterBlockConstant(first.p.data());
    problem.SetParameterBlockConstant(first.q.coeffs().data());
  }

  ceres::Solver::Options sopts;
  sopts.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  sopts.max_num_iterations = options_.max_iterations;
  sopts.function_tolerance = options_.function_tolerance;
  sopts.num_threads = 1;
  sopts.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(sopts, &problem, &summary);
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.iterations = static_cast<int>(summary.iterations.size());
  out.initial_cost = summary.initial_cost;
  out.final_cost = summary.final_cost;
  for (auto& [id, b] : blocks) {
    Pose3 T = Pose3::Identity();
    T.linear() = b.q.normalized().toRotationMatrix();
    T.translation() = b.p;
    poses_[id] = T;
  }
  return out;
}

Mat6 relativeInformation(const Mat6& cov_from, const Mat6& cov_to, double rotation_floor_rad, double translation_floor_m) {
  Mat6 d = cov_to - cov_from;
  d = 0.5 * (d + d.transpose());
  if (!d.allFinite()) d.setZero();
  Eigen::SelfAdjointEigenSolver<Mat6> es(d);
  Vec6 ev = es.eigenvalues().cwiseMax(0.0);
  Mat6 cov = es.eigenvectors() * ev.asDiagonal() * es.eigenvectors().transpose();
  for (int i = 0; i < 3; ++i) cov(i, i) += rotation_floor_rad * rotation_floor_rad;
  for (int i = 3; i < 6; ++i) cov(i, i) += translation_floor_m * translation_floor_m;
  return cov.inverse();
}

}  // namespace livo::loop
