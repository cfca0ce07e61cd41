#include "livo/lio/wheel_update.hpp"

#include <Eigen/Cholesky>

namespace livo::lio {

Vec3 wheelFrameVelocity(const FilterState& x, const Vec3& gyro, const Pose3& T_I_B) {
  const Mat3 R_IB = T_I_B.linear();
  const Vec3 t_IB = T_I_B.translation();
  return R_IB.transpose() * (x.rot.transpose() * x.vel + (gyro - x.gyro_bias).cross(t_IB));
}

Mat3xState wheelVelocityJacobian(const FilterState& x, const Vec3&, const Pose3& T_I_B) {
  using S = FilterState;
  const Mat3 R_IBt = T_I_B.linear().transpose();
  Mat3xState H = Mat3xState::Zero();
  // (R Exp(δr))^T v ≈ R^T v + [R^T v]x δr;  (ω - δb) × t = ω × t + [t]x δb
  H.block<3, 3>(0, S::kRot) = R_IBt * so3::hat(x.rot.transpose() * x.vel);
  H.block<3, 3>(0, S::kVel) = R_IBt * x.rot.transpose();
  H.block<3, 3>(0, S::kGyroBias) = R_IBt * so3::hat(T_I_B.translation());
  return H;
}

WheelUpdateResult wheelVelocityUpdate(FilterState* x, StateCovariance* P, const Vec3& gyro, double forward_speed,
                                      const WheelOptions& o, double extra_forward_variance) {
  WheelUpdateResult res;
  const Vec3 z = wheelFrameVelocity(*x, gyro, o.T_I_B) - Vec3(forward_speed, 0.0, 0.0);
  const Mat3xState H = wheelVelocityJacobian(*x, gyro, o.T_I_B);
  Mat3 R = Mat3::Zero();
  // the mean of two wheels: variance halves
  R.diagonal() << 0.5 * o.speed_noise_std * o.speed_noise_std + extra_forward_variance,
      o.lateral_noise_std * o.lateral_noise_std, o.vertical_noise_std * o.vertical_noise_std;
  const Eigen::Matrix<double, FilterState::kDim, 3> PHt = (*P) * H.transpose();
  const Mat3 Sinn = H * PHt + R;
  const Eigen::LLT<Mat3> llt(Sinn);
  if (llt.info() != Eigen::Success) return res;
  res.chi2 = z.dot(llt.solve(z));
  res.innovation = z;
  if (!(res.chi2 <= o.gate_chi2)) return res;
  const Eigen::Matrix<double, FilterState::kDim, 3> K = llt.solve(PHt.transpose()).transpose();
  const StateVector dx = -K * z;
  if (!dx.allFinite()) return res;
  *x = x->boxplus(dx);
  // Joseph form keeps P symmetric positive definite
  const StateCovariance IKH = StateCovariance::Identity() - K * H;
  StateCovariance Pn = IKH * (*P) * IKH.transpose() + K * R * K.transpose();
  *P = 0.5 * (Pn + Pn.transpose());
  res.applied = true;
  return res;
}

}  // namespace livo::lio
