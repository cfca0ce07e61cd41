#include "livo/lio/imu_intrinsics.hpp"

namespace livo::lio {

namespace {
constexpr int kCrossRow[6] = {0, 0, 1, 1, 2, 2};
constexpr int kCrossCol[6] = {1, 2, 0, 2, 0, 1};
}  // namespace

Mat3 ImuIntrinsics::axes(const Vec3& scale, const Eigen::Matrix<double, 6, 1>& cross) {
  Mat3 K = Mat3::Identity();
  K.diagonal() += scale;
  for (int e = 0; e < 6; ++e) K(kCrossRow[e], kCrossCol[e]) = cross[e];
  return K;
}

Eigen::Matrix<double, 3, 9> ImuIntrinsics::readingJacobian(const Mat3& K, const Vec3& w) {
  // ∂(K^-1 u) = -K^-1 ∂K K^-1 u = -K^-1 ∂K w, and ∂K/∂K_ij = e_i e_j^T
  const Mat3 K_inv = K.inverse();
  Eigen::Matrix<double, 3, 9> J;
  for (int i = 0; i < 3; ++i) J.col(i) = -K_inv.col(i) * w[i];
  for (int e = 0; e < 6; ++e) J.col(3 + e) = -K_inv.col(kCrossRow[e]) * w[kCrossCol[e]];
  return J;
}

Vec3 ImuIntrinsics::angularVelocity(const Vec3& gyro, const Vec3& gyro_bias) const {
  return gyroAxes().inverse() * (gyro - gyro_bias);
}

Vec3 ImuIntrinsics::specificForce(const Vec3& accel, const Vec3& accel_bias) const {
  return accelAxes().inverse() * (accel - accel_bias);
}

ImuIntrinsics::Covariance intrinsicsPrior(double gyro_scale_std, double gyro_misalignment_std, double accel_scale_std,
                                          double accel_misalignment_std) {
  ImuIntrinsics::Covariance P = ImuIntrinsics::Covariance::Zero();
  P.diagonal().segment<3>(ImuIntrinsics::kGyroScale).setConstant(gyro_scale_std * gyro_scale_std);
  P.diagonal().segment<6>(ImuIntrinsics::kGyroCross).setConstant(gyro_misalignment_std * gyro_misalignment_std);
  P.diagonal().segment<3>(ImuIntrinsics::kAccelScale).setConstant(accel_scale_std * accel_scale_std);
  P.diagonal().segment<6>(ImuIntrinsics::kAccelCross).setConstant(accel_misalignment_std * accel_misalignment_std);
  return P;
}

}  // namespace livo::lio
