// SO(3) and SE(3) on Eigen: exponential and logarithm maps with their Jacobians.
//
// Conventions (used across the project, the ESIKF included):
//  - rotation vectors are right perturbations: R ⊞ r = R Exp(r), R1 ⊟ R2 = Log(R2^T R1);
//  - Exp(a + d) ≈ Exp(a) Exp(Jr(a) d), Log(Exp(a) Exp(d)) ≈ a + JrInv(a) d;
//  - SE(3) tangent vectors are ordered [rotation; translation] and perturb on the right.
#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace livo {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Quat = Eigen::Quaterniond;
using Pose3 = Eigen::Isometry3d;

/// The angle between two vectors in degrees (0 if either is zero), accurate to rounding for
/// angles away from 0 and 180 degrees.
inline double angleBetweenDeg(const Vec3& a, const Vec3& b) {
  const double c = a.dot(b) / std::max(1e-12, a.norm() * b.norm());
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / M_PI;
}

namespace so3 {

/// Skew-symmetric matrix: hat(a) * b = a × b.
inline Mat3 hat(const Vec3& v) {
  Mat3 m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

/// Inverse of hat for a skew-symmetric matrix.
inline Vec3 vee(const Mat3& m) { return Vec3(m(2, 1), m(0, 2), m(1, 0)); }

/// Rodrigues' formula; exact to machine precision near zero.
Mat3 Exp(const Vec3& r);

/// Quaternion of Exp(r), unit norm.
Quat ExpQuat(const Vec3& r);

/// Rotation vector of R with angle in [0, pi]; robust near 0 and near pi.
Vec3 Log(const Mat3& R);
Vec3 Log(const Quat& q);

/// Right Jacobian of SO(3).
Mat3 rightJacobian(const Vec3& r);
/// Inverse of the right Jacobian.
Mat3 rightJacobianInverse(const Vec3& r);
/// Left Jacobian (= rightJacobian(-r)).
inline Mat3 leftJacobian(const Vec3& r) { return rightJacobian(-r); }

/// Projects a nearly orthonormal matrix onto SO(3).
Mat3 normalize(const Mat3& R);

}  // namespace so3

namespace se3 {

/// Exp of xi = [rotation; translation] (SE(3) exponential, not a decoupled product).
Pose3 Exp(const Vec6& xi);
/// Log of T as [rotation; translation].
Vec6 Log(const Pose3& T);

/// Pose from a rotation vector and a translation (decoupled, as the filter state stores it).
Pose3 fromRotationTranslation(const Mat3& R, const Vec3& t);

/// Interpolates between poses: slerp on rotation, linear on translation; alpha in [0, 1].
Pose3 interpolate(const Pose3& a, const Pose3& b, double alpha);

/// Decoupled right-perturbation difference [Log(Rb^T Ra); ta - tb] (the state's ⊟ on a pose).
Vec6 boxminus(const Pose3& a, const Pose3& b);
/// Decoupled right perturbation: (R Exp(d_rot), t + d_trans).
Pose3 boxplus(const Pose3& a, const Vec6& d);

/// Adjoint of T acting on [rotation; translation] tangent vectors.
Mat6 adjoint(const Pose3& T);

}  // namespace se3

}  // namespace livo
