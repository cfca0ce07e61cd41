// Orientations in the graph: unit quaternions perturbed on the right (q Exp(dtheta)), the convention
// of every information matrix here, and the square root of an information matrix.
#pragma once

#include <ceres/manifold.h>
#include <Eigen/Core>

namespace livo {

/// Unit quaternions (x, y, z, w) with Plus(q, d) = q * Exp(d) and Minus(y, x) = Log(x^-1 * y).
class RightQuaternionManifold : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 4; }
  int TangentSize() const override { return 3; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;  // 4x3 row-major
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;  // 3x4 row-major
};

/// The left inverse of PlusJacobian(q) (3x4): an analytic Jacobian J with respect to the right
/// perturbation (rows x 3) times this is an ambient Jacobian that Ceres, multiplying it by
/// PlusJacobian, turns back into J. For cost functions with hand-written Jacobians.
Eigen::Matrix<double, 3, 4> tangentToAmbient(const double* q);

/// d Log(x0^-1 q) / dq (3x4, row-major ambient Jacobian) such that, times PlusJacobian(q), it gives
/// Jr^-1 of the difference: what a linear prior in the tangent space needs.
void minusAmbientJacobian(const double* q0, const double* q, double* jacobian);

/// A square root information matrix of `information` (symmetric, positive semidefinite): S^T S =
/// information, eigenvalues below zero clipped.
Eigen::MatrixXd sqrtInformation(const Eigen::MatrixXd& information);

}  // namespace livo
