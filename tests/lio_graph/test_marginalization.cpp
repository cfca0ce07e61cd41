// Marginalisation against the full problem: eliminating a block and keeping its linear prior gives
// the full problem's estimate and covariance of the blocks that stay (exactly for a linear problem,
// to first order on quaternions); the quaternion manifold's Jacobians against numeric ones; the
// prior moved with a rigid correction of the world (a loop correction).
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <stdexcept>

#include "livo/graph_factors.hpp"
#include "livo/lio_graph/plane_factor.hpp"
#include "livo/marginalization.hpp"

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
  ceres::CostFunction* prior0 =
      makePoseFactor(se3::fromRotationTranslation(so3::Exp(Vec3(0.1, 0.2, -0.3)), Vec3::Zero()), info0);
  ceres::CostFunction* prior2 =
      makePoseFactor(se3::fromRotationTranslation(so3::Exp(Vec3(0.5, -0.1, 0.4)), Vec3::Zero()), info2);
  ceres::CostFunction* r01 =
      new ceres::AutoDiffCostFunction<RelativeRotation, 3, 4, 4>(new RelativeRotation{rq().inverse(), 10.0});
  ceres::CostFunction* r12 =
      new ceres::AutoDiffCostFunction<RelativeRotation, 3, 4, 4>(new RelativeRotation{rq().inverse(), 10.0});
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

namespace {

/// A state of the window as the estimator holds it: orientation (x y z w), position, velocity, biases.
struct State {
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Vec3 p = Vec3::Zero(), v = Vec3::Zero(), bg = Vec3::Zero(), ba = Vec3::Zero();
  Pose3 pose() const { return se3::fromRotationTranslation(q.toRotationMatrix(), p); }
};

/// The state in the world moved by T: orientation and position by T, velocity turned, biases kept.
State movedState(const State& s, const Pose3& T) {
  State m = s;
  m.q = (Eigen::Quaterniond(T.linear()) * s.q).normalized();
  m.p = T * s.p;
  m.v = T.linear() * s.v;
  return m;
}

/// A pose factor's information in a world turned by R (the position error turns with it).
Mat6 turned(const Mat6& information, const Mat3& R) {
  Mat6 A = Mat6::Identity();
  A.bottomRightCorner<3, 3>() = R;
  return A * information * A.transpose();
}

Mat6 randomInformation(std::mt19937& rng) {
  std::normal_distribution<double> g;
  Mat6 A;
  for (int i = 0; i < 36; ++i) A(i) = g(rng);
  return A * A.transpose() + 10.0 * Mat6::Identity();
}

Eigen::VectorXd evaluate(const ceres::CostFunction& f, const std::vector<double*>& blocks) {
  Eigen::VectorXd r(f.num_residuals());
  EXPECT_TRUE(f.Evaluate(blocks.data(), r.data(), nullptr));
  return r;
}

/// The two states, the landmark's c and its anchor, and the factors of a small window, made in a
/// world frame (gravity, anchor and measured poses given in it).
struct SmallWindow {
  State a, b;
  Vec3 c = Vec3::Zero(), anchor = Vec3::Zero();
  std::unique_ptr<ceres::CostFunction> prior_a, imu, walk, plane_a, plane_b, lidar_b;

  /// Marginalises state a: the prior on b's blocks and c.
  std::shared_ptr<MarginalPrior> marginalizeA() {
    Marginalizer m;
    m.setQuaternion(a.q.coeffs().data());
    m.setQuaternion(b.q.coeffs().data());
    m.addFactor(prior_a.get(), {a.q.coeffs().data(), a.p.data()});
    m.addFactor(imu.get(), {a.q.coeffs().data(), a.p.data(), a.v.data(), a.bg.data(), a.ba.data(), b.q.coeffs().data(),
                            b.p.data(), b.v.data()});
    m.addFactor(walk.get(), {a.bg.data(), a.ba.data(), b.bg.data(), b.ba.data()});
    m.addFactor(plane_a.get(), {a.q.coeffs().data(), a.p.data(), c.data()});
    m.addFactor(plane_b.get(), {b.q.coeffs().data(), b.p.data(), c.data()});
    m.addFactor(lidar_b.get(), {b.q.coeffs().data(), b.p.data()});
    return m.marginalize({a.q.coeffs().data(), a.p.data(), a.v.data(), a.bg.data(), a.ba.data()});
  }
  /// The prior's blocks as the estimator tells them apart.
  std::vector<WorldMotion> motions(const MarginalPrior& prior) {
    std::vector<WorldMotion> m;
    for (const double* blk : prior.blocks) {
      if (blk == b.q.coeffs().data())
        m.push_back(WorldMotion::kRotation);
      else if (blk == b.p.data())
        m.push_back(WorldMotion::kPoint);
      else if (blk == b.v.data() || blk == c.data())
        m.push_back(WorldMotion::kDirection);
      else
        m.push_back(WorldMotion::kNone);
    }
    return m;
  }
};

}  // namespace

// A loop correction moves the window rigidly: the marginal prior moved with it (linearisation
// points moved, the columns of world-frame tangents turned) gives the same residual at the moved
// state as before at the old one, its Jacobians are right, and it is the prior the same
// marginalisation would have produced in the moved world.
TEST(Marginalization, PriorMovesWithARigidCorrectionOfTheWorld) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g;
  auto rv = [&](double s) { return Vec3(s * g(rng), s * g(rng), s * g(rng)); };
  const Vec3 gravity(0.0, 0.0, -9.81);
  ImuPreintegration pre(Vec3(0.01, -0.02, 0.005), Vec3(0.05, 0.02, -0.03), ImuPreintegrationNoise{});
  for (int k = 0; k < 20; ++k) pre.integrate(Vec3(0.1, -0.2, 0.3) + rv(0.01), Vec3(0.5, 0.2, 9.9) + rv(0.05), 0.005);

  SmallWindow w;
  w.a.q = so3::ExpQuat(rv(0.3));
  w.a.p = rv(1.0);
  w.a.v = rv(0.5);
  w.a.bg = rv(0.01);
  w.a.ba = rv(0.05);
  w.b.q = w.a.q * so3::ExpQuat(Vec3(0.01, -0.02, 0.03) + rv(0.01));
  w.b.p = w.a.p + 0.1 * w.a.v + rv(0.02);
  w.b.v = w.a.v + rv(0.05);
  w.b.bg = w.a.bg + rv(0.001);
  w.b.ba = w.a.ba + rv(0.005);
  w.anchor = w.a.p;
  w.c = Vec3(0.3, -0.2, 2.0) + rv(0.05);
  const Vec3 n_a = Vec3(0.1, 0.05, -1.0).normalized(), n_b = Vec3(0.12, 0.03, -1.0).normalized();
  const Pose3 measured_a = se3::boxplus(w.a.pose(), (Vec6() << rv(0.01), rv(0.02)).finished());
  const Pose3 measured_b = se3::boxplus(w.b.pose(), (Vec6() << rv(0.01), rv(0.02)).finished());
  const Mat6 info_a = randomInformation(rng), info_b = randomInformation(rng);
  auto makeFactors = [&](SmallWindow& win, const Pose3& T) {
    win.prior_a.reset(makePoseFactor(T * measured_a, turned(info_a, T.linear())));
    win.imu.reset(makeImuFactor(pre, T.linear() * gravity));
    win.walk.reset(makeBiasWalkFactor(1e-4, 1e-3, 0.1));
    win.plane_a.reset(makePlaneFactor(win.anchor, n_a, 2.05, 0.02, 0.05));
    win.plane_b.reset(makePlaneFactor(win.anchor, n_b, 1.98, 0.02, 0.05));
    win.lidar_b.reset(makePoseFactor(T * measured_b, turned(info_b, T.linear())));
  };
  makeFactors(w, Pose3::Identity());
  const auto prior = w.marginalizeA();
  ASSERT_TRUE(prior);
  auto blocksOf = [](State& s, Vec3& c) {
    return std::vector<double*>{s.q.coeffs().data(), s.p.data(), s.v.data(), s.bg.data(), s.ba.data(), c.data()};
  };
  ASSERT_EQ(prior->blocks, blocksOf(w.b, w.c));  // b's five blocks and c, in the order they were first seen
  const std::vector<WorldMotion> motion = w.motions(*prior);

  // a 5 deg yaw, a little roll and pitch, and a translation
  const Pose3 T = se3::fromRotationTranslation(so3::Exp(Vec3(0.02, -0.015, 5.0 * M_PI / 180.0)), Vec3(3.0, -2.0, 0.5));
  const auto moved = std::make_shared<MarginalPrior>(movedPrior(*prior, motion, T));
  EXPECT_EQ(moved->blocks, prior->blocks);
  MarginalPriorFactor before(prior), after(moved);

  // the moved world: the same window remade there and marginalised again
  SmallWindow mw;
  mw.a = movedState(w.a, T);
  mw.b = movedState(w.b, T);
  mw.c = T.linear() * w.c;
  mw.anchor = T * w.anchor;
  makeFactors(mw, T);
  const auto remade = mw.marginalizeA();
  ASSERT_TRUE(remade);
  MarginalPriorFactor again(remade);

  ASSERT_EQ(remade->blocks, blocksOf(mw.b, mw.c));
  for (int trial = 0; trial < 4; ++trial) {
    // at the linearisation point, then at states away from it
    State x = w.b;
    Vec3 c = w.c;
    if (trial > 0) {
      x.q = x.q * so3::ExpQuat(rv(0.05));
      x.p += rv(0.1);
      x.v += rv(0.1);
      x.bg += rv(0.001);
      x.ba += rv(0.01);
      c += rv(0.05);
    }
    State xm = movedState(x, T);
    Vec3 cm = T.linear() * c;
    const Eigen::VectorXd r_old = evaluate(before, blocksOf(x, c));
    const Eigen::VectorXd r_new = evaluate(after, blocksOf(xm, cm));
    EXPECT_LT((r_new - r_old).norm(), 1e-9) << trial << ": " << r_old.norm();
    // the prior marginalised in the moved world: the same cost (its rows may be another basis)
    const Eigen::VectorXd r_again = evaluate(again, blocksOf(xm, cm));
    EXPECT_NEAR(r_again.squaredNorm(), r_new.squaredNorm(), 1e-8 * (1.0 + r_new.squaredNorm())) << trial;

    // analytic Jacobians of the moved prior against numeric ones, in each block's tangent space
    std::vector<double*> blocks = blocksOf(xm, cm);
    const int rows = after.num_residuals();
    std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(blocks.size());
    std::vector<double*> jac(blocks.size());
    for (size_t k = 0; k < blocks.size(); ++k) {
      J[k].resize(rows, k == 0 ? 4 : 3);
      jac[k] = J[k].data();
    }
    Eigen::VectorXd r(rows);
    ASSERT_TRUE(after.Evaluate(blocks.data(), r.data(), jac.data()));
    const RightQuaternionManifold manifold;
    const double h = 1e-6;
    for (size_t k = 0; k < blocks.size(); ++k) {
      Eigen::MatrixXd analytic = J[k];
      if (k == 0) {
        Eigen::Matrix<double, 4, 3, Eigen::RowMajor> P;
        manifold.PlusJacobian(blocks[0], P.data());
        analytic = J[0] * P;
      }
      for (int d = 0; d < 3; ++d) {
        std::vector<double> plus(blocks[k], blocks[k] + (k == 0 ? 4 : 3)), minus = plus;
        if (k == 0) {
          Vec3 e = Vec3::Zero();
          e(d) = h;
          manifold.Plus(blocks[0], e.data(), plus.data());
          e(d) = -h;
          manifold.Plus(blocks[0], e.data(), minus.data());
        } else {
          plus[d] += h;
          minus[d] -= h;
        }
        std::vector<double*> bp = blocks, bm = blocks;
        bp[k] = plus.data();
        bm[k] = minus.data();
        const Eigen::VectorXd numeric = (evaluate(after, bp) - evaluate(after, bm)) / (2.0 * h);
        EXPECT_LT((numeric - analytic.col(d)).norm(), 1e-6 * (1.0 + analytic.col(d).norm()))
            << "trial " << trial << ", block " << k << ", direction " << d;
      }
    }
  }

  // a motion that does not fit its block is refused
  std::vector<WorldMotion> wrong = motion;
  wrong[1] = WorldMotion::kRotation;  // b.p is Euclidean
  EXPECT_THROW(movedPrior(*prior, wrong, T), std::invalid_argument);
  EXPECT_THROW(movedPrior(*prior, {WorldMotion::kNone}, T), std::invalid_argument);
}

// The correlated vector prior (the first state's accelerometer bias: tight along "up", loose across):
// its squared residual is the Mahalanobis distance and its Jacobian's J^T J the information.
TEST(GraphFactors, CorrelatedVectorPriorIsTheMahalanobisDistance) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  for (int trial = 0; trial < 5; ++trial) {
    Mat3 A;
    for (int i = 0; i < 9; ++i) A(i) = g(rng);
    const Mat3 covariance = A * A.transpose() + 1e-3 * Mat3::Identity();
    const Vec3 mean(g(rng), g(rng), g(rng)), x(g(rng), g(rng), g(rng));
    std::unique_ptr<ceres::CostFunction> cost(makeCorrelatedVectorPriorFactor(mean, covariance));
    const double* params[] = {x.data()};
    Vec3 r;
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> J;
    double* jacobians[] = {J.data()};
    ASSERT_TRUE(cost->Evaluate(params, r.data(), jacobians));
    const Mat3 information = covariance.inverse();
    EXPECT_NEAR(r.squaredNorm(), (x - mean).dot(information * (x - mean)), 1e-9 * (1.0 + r.squaredNorm()));
    EXPECT_LT((Mat3(J.transpose() * J) - information).norm(), 1e-8 * information.norm());
  }
  // The start at rest: 2 mm/s^2 along up, 0.05 across; a bias error along up costs 625x one across.
  const Vec3 up(0.0, 0.0, 1.0);
  const Mat3 at_rest = 0.05 * 0.05 * Mat3::Identity() + (0.002 * 0.002 - 0.05 * 0.05) * up * up.transpose();
  std::unique_ptr<ceres::CostFunction> prior(makeCorrelatedVectorPriorFactor(Vec3::Zero(), at_rest));
  auto cost2 = [&](const Vec3& b) {
    const double* params[] = {b.data()};
    Vec3 r;
    prior->Evaluate(params, r.data(), nullptr);
    return r.squaredNorm();
  };
  EXPECT_NEAR(cost2(Vec3(0, 0, 0.01)) / cost2(Vec3(0.01, 0, 0)), 625.0, 1e-6);
}
