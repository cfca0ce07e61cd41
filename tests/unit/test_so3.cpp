// SO(3)/SE(3) maps and every Jacobian against numeric differentiation.
#include <gtest/gtest.h>

#include <random>

#include "livo/so3.hpp"

using namespace livo;

namespace {

std::vector<Vec3> testVectors() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> v = {Vec3::Zero(),         Vec3(1e-9, -2e-9, 3e-9), Vec3(1e-6, 0, 0),
                         Vec3(0.3, -0.2, 0.1), Vec3(0, 0, M_PI - 1e-4), Vec3(2.0, 1.0, -0.5).normalized() * 3.0};
  for (int i = 0; i < 20; ++i) v.push_back(Vec3(u(rng), u(rng), u(rng)) * 2.5);
  return v;
}

// Central differences of f: R^3 -> R^3 at x.
template <class F>
Mat3 numericJacobian(F f, const Vec3& x, double h = 1e-6) {
  Mat3 J;
  for (int i = 0; i < 3; ++i) {
    Vec3 dx = Vec3::Zero();
    dx[i] = h;
    J.col(i) = (f(x + dx) - f(x - dx)) / (2 * h);
  }
  return J;
}

}  // namespace

TEST(So3, ExpLogRoundTrip) {
  for (const Vec3& r : testVectors()) {
    const Mat3 R = so3::Exp(r);
    EXPECT_NEAR((R.transpose() * R - Mat3::Identity()).norm(), 0.0, 1e-12);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
    Vec3 back = so3::Log(R);
    // angles above pi wrap: compare rotations
    EXPECT_NEAR((so3::Exp(back) - R).norm(), 0.0, 1e-9) << r.transpose();
    if (r.norm() < M_PI - 1e-3) {
      EXPECT_NEAR((back - r).norm(), 0.0, 1e-9) << r.transpose();
    }
  }
}

TEST(So3, ExpMatchesAngleAxisAndQuaternion) {
  for (const Vec3& r : testVectors()) {
    const double th = r.norm();
    const Mat3 ref = th > 0 ? Eigen::AngleAxisd(th, r / th).toRotationMatrix() : Mat3::Identity();
    EXPECT_NEAR((so3::Exp(r) - ref).norm(), 0.0, 1e-12);
    EXPECT_NEAR((so3::ExpQuat(r).toRotationMatrix() - ref).norm(), 0.0, 1e-12);
  }
}

TEST(So3, LogNearPi) {
  const Vec3 axis = Vec3(1, 2, 3).normalized();
  for (double eps : {1e-3, 1e-6, 1e-9}) {
    const Mat3 R = Eigen::AngleAxisd(M_PI - eps, axis).toRotationMatrix();
    const Vec3 r = so3::Log(R);
    EXPECT_NEAR(r.norm(), M_PI - eps, 1e-7);
    EXPECT_NEAR(std::abs(r.normalized().dot(axis)), 1.0, 1e-7);
  }
}

TEST(So3, HatVee) {
  const Vec3 a(1, -2, 3), b(-0.5, 4, 2);
  EXPECT_NEAR((so3::hat(a) * b - a.cross(b)).norm(), 0.0, 1e-15);
  EXPECT_EQ(so3::vee(so3::hat(a)), a);
}

// Exp(r + d) ≈ Exp(r) Exp(Jr(r) d)  =>  Jr = ∂ Log(Exp(r)^T Exp(r + d)) / ∂d.
TEST(So3, RightJacobianNumeric) {
  for (const Vec3& r : testVectors()) {
    if (r.norm() > M_PI - 1e-2) continue;  // Log wraps there
    const Mat3 R0 = so3::Exp(r);
    const Mat3 Jnum = numericJacobian([&](const Vec3& x) { return so3::Log(Mat3(R0.transpose() * so3::Exp(x))); }, r);
    EXPECT_NEAR((so3::rightJacobian(r) - Jnum).norm(), 0.0, 1e-7) << r.transpose();
  }
}

// Log(Exp(r) Exp(d)) ≈ r + JrInv(r) d  =>  JrInv = ∂ Log(Exp(r) Exp(d)) / ∂d at d = 0.
TEST(So3, RightJacobianInverseNumeric) {
  for (const Vec3& r : testVectors()) {
    if (r.norm() > M_PI - 1e-2) continue;
    const Mat3 R0 = so3::Exp(r);
    const Mat3 Jnum = numericJacobian([&](const Vec3& d) { return so3::Log(Mat3(R0 * so3::Exp(d))); }, Vec3::Zero());
    EXPECT_NEAR((so3::rightJacobianInverse(r) - Jnum).norm(), 0.0, 1e-7) << r.transpose();
    EXPECT_NEAR((so3::rightJacobianInverse(r) * so3::rightJacobian(r) - Mat3::Identity()).norm(), 0.0, 1e-9);
  }
}

// Exp(r + d) ≈ Exp(Jl(r) d) Exp(r).
TEST(So3, LeftJacobianNumeric) {
  for (const Vec3& r : testVectors()) {
    if (r.norm() > M_PI - 1e-2) continue;
    const Mat3 R0 = so3::Exp(r);
    const Mat3 Jnum = numericJacobian([&](const Vec3& x) { return so3::Log(Mat3(so3::Exp(x) * R0.transpose())); }, r);
    EXPECT_NEAR((so3::leftJacobian(r) - Jnum).norm(), 0.0, 1e-7) << r.transpose();
  }
}

// ∂(R Exp(d) p)/∂d = -R hat(p), the point Jacobian every residual uses.
TEST(So3, RotatedPointJacobianNumeric) {
  const Mat3 R = so3::Exp(Vec3(0.4, -0.3, 1.2));
  const Vec3 p(2.0, -1.0, 0.5);
  const Mat3 Jnum = numericJacobian([&](const Vec3& d) { return Vec3(R * so3::Exp(d) * p); }, Vec3::Zero());
  EXPECT_NEAR((-R * so3::hat(p) - Jnum).norm(), 0.0, 1e-8);
}

TEST(Se3, ExpLogRoundTrip) {
  for (const Vec3& r : testVectors()) {
    if (r.norm() > M_PI - 1e-2) continue;
    Vec6 xi;
    xi << r, Vec3(1.0, -2.0, 0.5) + r;
    const Pose3 T = se3::Exp(xi);
    EXPECT_NEAR((se3::Log(T) - xi).norm(), 0.0, 1e-9);
  }
}

TEST(Se3, ExpMatchesMatrixExponential) {
  // Integrate the twist in many small steps: T = prod Exp(xi / n) -> exp of the 4x4 twist.
  Vec6 xi;
  xi << 0.3, -0.5, 0.8, 1.0, 2.0, -1.0;
  Pose3 T = Pose3::Identity();
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    Pose3 step = Pose3::Identity();
    step.linear() = so3::Exp(xi.head<3>() / n);
    step.translation() = xi.tail<3>() / n;
    T = T * step;
  }
  EXPECT_NEAR((T.matrix() - se3::Exp(xi).matrix()).norm(), 0.0, 1e-4);
}

// Ad(T) maps a right perturbation to a left one: T Exp(xi) = Exp(Ad(T) xi) T.
TEST(Se3, AdjointNumeric) {
  Vec6 t;
  t << 0.2, -0.1, 0.7, 1.0, -3.0, 2.0;
  const Pose3 T = se3::Exp(t);
  Vec6 xi;
  xi << 1e-3, -2e-3, 0.5e-3, 2e-3, 1e-3, -1e-3;
  const Pose3 lhs = T * se3::Exp(xi);
  const Pose3 rhs = se3::Exp(se3::adjoint(T) * xi) * T;
  EXPECT_NEAR((lhs.matrix() - rhs.matrix()).norm(), 0.0, 1e-12);
}

TEST(Se3, BoxPlusMinusAndInterpolate) {
  Vec6 t;
  t << 0.2, -0.1, 0.7, 1.0, -3.0, 2.0;
  const Pose3 A = se3::Exp(t);
  Vec6 d;
  d << 0.01, 0.02, -0.03, 0.1, -0.2, 0.3;
  const Pose3 B = se3::boxplus(A, d);
  EXPECT_NEAR((se3::boxminus(B, A) - d).norm(), 0.0, 1e-12);
  const Pose3 M0 = se3::interpolate(A, B, 0.0), M1 = se3::interpolate(A, B, 1.0), Mh = se3::interpolate(A, B, 0.5);
  EXPECT_NEAR((M0.matrix() - A.matrix()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((M1.matrix() - B.matrix()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((se3::boxminus(Mh, A) - 0.5 * d).norm(), 0.0, 1e-9);
}
