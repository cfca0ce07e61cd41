#include "livo/so3.hpp"

#include <cmath>

namespace livo {
namespace so3 {

namespace {
// Below this angle the closed forms lose precision; Taylor series take over.
constexpr double kSmallAngle = 1e-5;
}  // namespace

Mat3 Exp(const Vec3& r) {
  const double theta2 = r.squaredNorm();
  const double theta = std::sqrt(theta2);
  const Mat3 K = hat(r);
  double a, b;  // R = I + a K + b K^2
  if (theta < kSmallAngle) {
    a = 1.0 - theta2 / 6.0;
    b = 0.5 - theta2 / 24.0;
  } else {
    a = std::sin(theta) / theta;
    b = (1.0 - std::cos(theta)) / theta2;
  }
  return Mat3::Identity() + a * K + b * K * K;
}

Quat ExpQuat(const Vec3& r) {
  const double theta = r.norm();
  const double half = 0.5 * theta;
  double k;  // sin(theta/2) / theta
  if (theta < kSmallAngle) {
    k = 0.5 - theta * theta / 48.0;
  } else {
    k = std::sin(half) / theta;
  }
  Quat q(std::cos(half), k * r.x(), k * r.y(), k * r.z());
  q.normalize();
  return q;
}

Vec3 Log(const Quat& q_in) {
  Quat q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // angle in [0, pi]
  const Vec3 v = q.vec();
  const double n = v.norm();
  const double w = q.w();
  double k;  // theta / sin(theta/2), theta = 2 atan2(n, w)
  if (n < kSmallAngle) {
    // atan2(n, w) ≈ n/w - n^3/(3 w^3)
    k = 2.0 / w * (1.0 - n * n / (3.0 * w * w));
  } else {
    k = 2.0 * std::atan2(n, w) / n;
  }
  return k * v;
}

Vec3 Log(const Mat3& R) { return Log(Quat(R)); }

Mat3 rightJacobian(const Vec3& r) {
  const double theta2 = r.squaredNorm();
  const Mat3 K = hat(r);
  if (theta2 < kSmallAngle * kSmallAngle) {
    return Mat3::Identity() - 0.5 * K + K * K / 6.0;
  }
  const double theta = std::sqrt(theta2);
  const double a = (1.0 - std::cos(theta)) / theta2;
  const double b = (theta - std::sin(theta)) / (theta2 * theta);
  return Mat3::Identity() - a * K + b * K * K;
}

Mat3 rightJacobianInverse(const Vec3& r) {
  const double theta2 = r.squaredNorm();
  const Mat3 K = hat(r);
  if (theta2 < kSmallAngle * kSmallAngle) {
    return Mat3::Identity() + 0.5 * K + K * K / 12.0;
  }
  const double theta = std::sqrt(theta2);
  const double c = 1.0 / theta2 - (1.0 + std::cos(theta)) / (2.0 * theta * std::sin(theta));
  return Mat3::Identity() + 0.5 * K + c * K * K;
}

Mat3 normalize(const Mat3& R) { return Quat(R).normalized().toRotationMatrix(); }

}  // namespace so3

namespace se3 {

namespace {
// V = Jl(phi): maps the translational part of the twist to the translation.
Mat3 leftJ(const Vec3& phi) { return so3::leftJacobian(phi); }
}  // namespace

Pose3 Exp(const Vec6& xi) {
  const Vec3 phi = xi.head<3>();
  const Vec3 rho = xi.tail<3>();
  Pose3 T = Pose3::Identity();
  T.linear() = so3::Exp(phi);
  T.translation() = leftJ(phi) * rho;
  return T;
}

Vec6 Log(const Pose3& T) {
  Vec6 xi;
  const Vec3 phi = so3::Log(Mat3(T.linear()));
  xi.head<3>() = phi;
  // Jl(phi)^-1 = Jr(-phi)^-1
  xi.tail<3>() = so3::rightJacobianInverse(-phi) * T.translation();
  return xi;
}

Pose3 fromRotationTranslation(const Mat3& R, const Vec3& t) {
  Pose3 T = Pose3::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

Pose3 interpolate(const Pose3& a, const Pose3& b, double alpha) {
  const Quat qa(a.linear()), qb(b.linear());
  Pose3 T = Pose3::Identity();
  T.linear() = qa.slerp(alpha, qb).toRotationMatrix();
  T.translation() = (1.0 - alpha) * a.translation() + alpha * b.translation();
  return T;
}

Vec6 boxminus(const Pose3& a, const Pose3& b) {
  Vec6 d;
  d.head<3>() = so3::Log(Mat3(b.linear().transpose() * a.linear()));
  d.tail<3>() = a.translation() - b.translation();
  return d;
}

Pose3 boxplus(const Pose3& a, const Vec6& d) {
  Pose3 T = Pose3::Identity();
  T.linear() = a.linear() * so3::Exp(d.head<3>());
  T.translation() = a.translation() + d.tail<3>();
  return T;
}

Mat6 adjoint(const Pose3& T) {
  Mat6 A = Mat6::Zero();
  const Mat3 R = T.linear();
  A.block<3, 3>(0, 0) = R;
  A.block<3, 3>(3, 3) = R;
  A.block<3, 3>(3, 0) = so3::hat(T.translation()) * R;
  return A;
}

}  // namespace se3
}  // namespace livo
