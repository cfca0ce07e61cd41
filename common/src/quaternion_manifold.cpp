#include "livo/quaternion_manifold.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "livo/so3.hpp"

namespace livo {

namespace {

using Quatd = Eigen::Quaterniond;

Eigen::Matrix<double, 4, 3> plusJacobianOf(const double* x) {
  // d(q * [d/2, 1]) / dd at 0, rows (x, y, z, w)
  const Eigen::Map<const Quatd> q(x);
  Eigen::Matrix<double, 4, 3> J;
  J.topRows<3>() = 0.5 * (q.w() * Mat3::Identity() + so3::hat(q.vec()));
  J.row(3) = -0.5 * q.vec().transpose();
  return J;
}

}  // namespace

Eigen::Matrix<double, 3, 4> tangentToAmbient(const double* q) { return 4.0 * plusJacobianOf(q).transpose(); }

bool RightQuaternionManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::Map<const Quatd> q(x);
  Eigen::Map<Quatd> out(x_plus_delta);
  out = (q * so3::ExpQuat(Vec3(delta[0], delta[1], delta[2]))).normalized();
  return true;
}

bool RightQuaternionManifold::PlusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 4, 3, Eigen::RowMajor>> out_map(jacobian);
  out_map = plusJacobianOf(x);
  return true;
}

bool RightQuaternionManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const Eigen::Map<const Quatd> qy(y), qx(x);
  Eigen::Map<Vec3> out_map(y_minus_x);
  out_map = so3::Log(Quat(qx.inverse() * qy));
  return true;
}

bool RightQuaternionManifold::MinusJacobian(const double* x, double* jacobian) const {
  // at y = x: the pseudo-inverse of PlusJacobian (its columns are orthogonal with norm 1/2)
  Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> out_map(jacobian);
  out_map = tangentToAmbient(x);
  return true;
}

void minusAmbientJacobian(const double* q0, const double* q, double* jacobian) {
  const Eigen::Map<const Quatd> a(q0), b(q);
  const Vec3 d = so3::Log(Quat(a.inverse() * b));
  Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> out_map(jacobian);
  out_map = so3::rightJacobianInverse(d) * 4.0 * plusJacobianOf(q).transpose();
}

Eigen::MatrixXd sqrtInformation(const Eigen::MatrixXd& information) {
  const Eigen::MatrixXd sym = 0.5 * (information + information.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(sym);
  const Eigen::VectorXd s = es.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return s.asDiagonal() * es.eigenvectors().transpose();
}

}  // namespace livo
