// Marginalisation against the full problem: eliminating a block and keeping its linear prior gives
// the full problem's estimate and covariance of the blocks that stay (exactly for a linear problem,
// to first order on quaternions); the quaternion manifold's Jacobians against numeric ones.
#include <gtest/gtest.h>

#include <random>

#include "livo/lio_graph/graph_factors.hpp"
#include "livo/lio_graph/marginalization.hpp"

using namespace livo;
using namespace livo::lio_graph;

namespace {

/// r = A (x_j - x_i - m) for 3-vectors (a linear "odometry" factor).
struct Between {
  Vec3 m;
  Mat3 A;
  template <class T>
  bool operator()(const T* xi, const T* xj, T* r) const {
    Eigen::Matrix<T, 3, 1> e;
    for (int k = 0; k < 3; ++k) e(k) = xj[k] - xi[k] - T(m(k));
    Eigen::Map<Eigen::Matrix<T, 3, 1>> out(r);
    out = A.cast<T>() * e;
    return true;
  }
};
/// r = A (x - m) (a unary factor).
struct Unary {
  Vec3 m;
  Mat3 A;
  template <class T>
  bool operator()(const T* x, T* r) const {
    Eigen::Matrix<T, 3, 1> e;
    for (int k = 0; k < 3; ++k) e(k) = x[k] - T(m(k));
    Eigen::Map<Eigen::Matrix<T, 3, 1>> out(r);
    out = A.cast<T>() * e;
    return true;
  }
};
/// Relative rotation q_i^-1 q_j against a measurement, on the tangent space.
struct RelativeRotation {
  Eigen::Quaterniond m_inv;
  double w;
  template <class T>
  bool operator()(const T* qi, const T* qj, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> a(qi), b(qj);
    const Eigen::Quaternion<T> e = m_inv.cast<T>() * a.conjugate() * b;
    for (int k = 0; k < 3; ++k) r[k] = T(2.0 * w) * e.vec()(k) * (e.w() < T(0) ? T(-1) : T(1));
    return true;
  }
};

Mat3 randomInfoSqrt(std::mt19937& rng) {
  std::normal_distribution<double> g;
  Mat3 A;
  for (int i = 0; i < 9; ++i) A(i) = g(rng);
  return A + 3.0 * Mat3::Identity();
}

}  // namespace

TEST(Marginalization, LinearChainMatchesTheFullProblem) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  auto rv = [&] { return Vec3(g(rng), g(rng), g(rng)); };
  Vec3 x[3] = {rv(), rv(), rv()};
  ceres::CostFunction* u0 = new ceres::AutoDiffCostFunction<Unary, 3, 3>(new Unary{rv(), randomInfoSqrt(rng)});
  ceres::CostFunction* b01 = new ceres::AutoDiffCostFunction<Between, 3, 3, 3>(new Between{rv(), randomInfoSqrt(rng)});
  ceres::CostFunction* b12 = new ceres::AutoDiffCostFunction<Between, 3, 3, 3>(new Between{rv(), randomInfoSqrt(rng)});
  ceres::CostFunction* u2 = new ceres::AutoDiffCostFunction<Unary, 3, 3>(new Unary{rv(), randomInfoSqrt(rng)});

  // the full problem
  ceres::Problem::Options keep;
  keep.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem full(keep);
  full.AddResidualBlock(u0, nullptr, x[0].data());
  full.AddResidualBlock(b01, nullptr, x[0].data(), x[1].data());
  full.AddResidualBlock(b12, nullptr, x[1].data(), x[2].data());
  full.AddResidualBlock(u2, nullptr, x[2].data());
  ceres::Solver::Options so;
  so.max_num_iterations = 20;
  so.function_tolerance = so.gradient_tolerance = so.parameter_tolerance = 1e-16;
  ceres::Solver::Summary sum;
  ceres::Solve(so, &full, &sum);
  const Vec3 x1_full = x[1], x2_full = x[2];
  ceres::Covariance::Options co;
  ceres::Covariance cov_full(co);
  const std::vector<std::pair<const double*, const double*>> block1{{x[1].data(), x[1].data()}};
  ASSERT_TRUE(cov_full.Compute(block1, &full));
  Mat3 C1_full;
  cov_full.GetCovarianceBlock(x[1].data(), x[1].data(), C1_full.data());

  // eliminate x0 somewhere else than at the optimum (a linear problem does not care)
  x[0] += Vec3(0.3, -0.2, 0.5);
  Marginalizer marg;
  marg.addFactor(u0, {x[0].data()});
  marg.addFactor(b01, {x[0].data(), x[1].data()});
  const auto prior = marg.marginalize({x[0].data()});
  ASSERT_TRUE(prior);
  ASSERT_EQ(prior->blocks.size(), 1u);
  EXPECT_EQ(prior->blocks[0], x[1].data());
  EXPECT_EQ(prior->J.rows(), 3);

  x[1] += Vec3(1, 1, 1);
  x[2] -= Vec3(1, 2, 3);
  ceres::Problem reduced(keep);
  MarginalPriorFactor prior_factor(prior);
  reduced.AddResidualBlock(&prior_factor, nullptr, x[1].data());
  reduced.AddResidualBlock(b12, nullptr, x[1].data(), x[2].data());
  reduced.AddResidualBlock(u2, nullptr, x[2].data());
  ceres::Solve(so, &reduced, &sum);
  EXPECT_LT((x[1] - x1_full).norm(), 1e-8);
  EXPECT_LT((x[2] - x2_full).norm(), 1e-8);
  ceres::Covariance cov_red(co);
  ASSERT_TRUE(cov_red.Compute(block1, &reduced));
  Mat3 C1_red;
  cov_red.GetCovarianceBlock(x[1].data(), x[1].data(), C1_red.data());
  EXPECT_LT((C1_red - C1_full).norm(), 1e-9 * C1_full.norm());
  delete u0;
  delete b01;
  delete b12;
  delete u2;
}

TEST(Marginalization, QuaternionChainMatchesTheFullProblemAtTheOptimum) {
  // three orientations: a pose prior on q0, relative rotations 0-1 and 1-2, a weak prior on q2
  std::mt19937 rng(9);
  std::normal_distribution<double> g(0.0, 0.3);
  auto rq = [&] { return Eigen::Quaterniond(so3::ExpQuat(Vec3(g(rng), g(rng), g(rng)))); };
  Eigen::Quaterniond q[3] = {rq(), rq(), rq()};
  Vec3 p[3] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  Mat6 info0 = Mat6::Identity() * 400.0, info2 = Mat6::Identity() * 4.0;
  ceres::CostFunction* prior0 = makePoseFactor(se3::fromRotationTranslation(so3::Exp(Vec3(0.1, 0.2, -0.3)), Vec3::Zero()), info0);
  ceres::CostFunction* prior2 = makePoseFactor(se3::fromRotationTranslation(so3::Exp(Vec3(0.5, -0.1, 0.4)), Vec3::Zero()), info2);
  ceres::CostFunction* r01 = new ceres::AutoDiffCostFunction<RelativeRotation, 3, 4, 4>(
      new RelativeRotation{rq().inverse(), 10.0});
  ceres::CostFunction* r12 = new ceres::AutoDiffCostFunction<RelativeRotation, 3, 4, 4>(
      new RelativeRotation{rq().inverse(), 10.0});
  ceres::Problem::Options keep;
  keep.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  keep.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  RightQuaternionManifold manifold;
  auto build = [&](ceres::Problem& pr, bool with_q0) {
    for (int i = with_q0 ? 0 : 1; i < 3; ++i) {
      pr.AddParameterBlock(q[i].coeffs().data(), 4, &manifold);
      pr.AddParameterBlock(p[i].data(), 3);
      pr.SetParameterBlockConstant(p[i].data());
    }
  };
  ceres::Problem full(keep);
  build(full, true);
  full.AddResidualBlock(prior0, nullptr, q[0].coeffs().data(), p[0].data());
  full.AddResidualBlock(r01, nullptr, q[0].coeffs().data(), q[1].coeffs().data());
  full.AddResidualBlock(r12, nullptr, q[1].coeffs().data(), q[2].coeffs().data());
  full.AddResidualBlock(prior2, nullptr, q[2].coeffs().data(), p[2].data());
  ceres::Solver::Options so;
  so.max_num_iterations = 50;
  so.function_tolerance = so.gradient_tolerance = so.parameter_tolerance = 1e-14;
  ceres::Solver::Summary sum;
  ceres::Solve(so, &full, &sum);
  const Eigen::Quaterniond q1 = q[1], q2 = q[2];

  Marginalizer marg;
  marg.setQuaternion(q[0].coeffs().data());
  marg.setQuaternion(q[1].coeffs().data());
  marg.addFactor(prior0, {q[0].coeffs().data(), p[0].data()});
  marg.addFactor(r01, {q[0].coeffs().data(), q[1].coeffs().data()});
  const auto prior = marg.marginalize({q[0].coeffs().data(), p[0].data()});
  ASSERT_TRUE(prior);
  ASSERT_EQ(prior->blocks.size(), 1u);

  q[1] = q[1] * so3::ExpQuat(Vec3(0.05, -0.04, 0.03));
  q[2] = q[2] * so3::ExpQuat(Vec3(-0.05, 0.02, 0.06));
  ceres::Problem reduced(keep);
  build(reduced, false);
  MarginalPriorFactor prior_factor(prior);
  reduced.AddResidualBlock(&prior_factor, nullptr, q[1].coeffs().data());
  reduced.AddResidualBlock(r12, nullptr, q[1].coeffs().data(), q[2].coeffs().data());
  reduced.AddResidualBlock(prior2, nullptr, q[2].coeffs().data(), p[2].data());
  ceres::Solve(so, &reduced, &sum);
  // linearised at the optimum: the reduced problem's optimum is the full one's (to second order in
  // the perturbation: the prior is linear where the eliminated factors were not)
  EXPECT_LT(so3::Log(Quat(q1.inverse() * q[1])).norm(), 1e-4);
  EXPECT_LT(so3::Log(Quat(q2.inverse() * q[2])).norm(), 1e-4);
  delete prior0;
  delete prior2;
  delete r01;
  delete r12;
}

TEST(GraphFactors, RightQuaternionManifoldJacobiansAgainstNumeric) {
  RightQuaternionManifold m;
  const Eigen::Quaterniond q(so3::ExpQuat(Vec3(0.3, -0.5, 0.8)));
  Eigen::Matrix<double, 4, 3, Eigen::RowMajor> J;
  m.PlusJacobian(q.coeffs().data(), J.data());
  const double h = 1e-6;
  for (int k = 0; k < 3; ++k) {
    Vec3 d = Vec3::Zero();
    d(k) = h;
    Eigen::Quaterniond a, b;
    m.Plus(q.coeffs().data(), d.data(), a.coeffs().data());
    m.Plus(q.coeffs().data(), Vec3(-d).data(), b.coeffs().data());
    const Eigen::Vector4d num = (a.coeffs() - b.coeffs()) / (2 * h);
    EXPECT_LT((num - J.col(k)).norm(), 1e-8);
  }
  // Minus inverts Plus
  const Vec3 d(0.1, -0.2, 0.05);
  Eigen::Quaterniond y;
  m.Plus(q.coeffs().data(), d.data(), y.coeffs().data());
  Vec3 back;
  m.Minus(y.coeffs().data(), q.coeffs().data(), back.data());
  EXPECT_LT((back - d).norm(), 1e-12);
  // the ambient Jacobian of so3::Log(q0^-1 q) times PlusJacobian(q) is Jr^-1
  Eigen::Matrix<double, 3, 4, Eigen::RowMajor> D;
  minusAmbientJacobian(q.coeffs().data(), y.coeffs().data(), D.data());
  Eigen::Matrix<double, 4, 3, Eigen::RowMajor> Py;
  m.PlusJacobian(y.coeffs().data(), Py.data());
  for (int k = 0; k < 3; ++k) {
    Vec3 e = Vec3::Zero();
    e(k) = h;
    Eigen::Quaterniond a, b;
    m.Plus(y.coeffs().data(), e.data(), a.coeffs().data());
    m.Plus(y.coeffs().data(), Vec3(-e).data(), b.coeffs().data());
    Vec3 la, lb;
    m.Minus(a.coeffs().data(), q.coeffs().data(), la.data());
    m.Minus(b.coeffs().data(), q.coeffs().data(), lb.data());
    EXPECT_LT(((la - lb) / (2 * h) - (D * Py).col(k)).norm(), 1e-7);
  }
}
