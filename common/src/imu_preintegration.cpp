#include "livo/imu_preintegration.hpp"

#include <algorithm>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace livo {

Eigen::MatrixXd upperSqrtInformation(const Eigen::MatrixXd& covariance) {
  const Eigen::MatrixXd sym = 0.5 * (covariance + covariance.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(sym);
  const double floor = std::max(1e-12 * eig.eigenvalues().maxCoeff(), 1e-18);
  const Eigen::VectorXd inverse = eig.eigenvalues().cwiseMax(floor).cwiseInverse();
  const Eigen::MatrixXd information = eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
  // information = L L^T = U^T U with U = L^T
  const Eigen::LLT<Eigen::MatrixXd> llt(0.5 * (information + information.transpose()));
  return llt.matrixU();
}

ImuPreintegrationNoise ImuPreintegrationNoise::fromRig(const ImuRig& rig) {
  ImuPreintegrationNoise n;
  n.gyro_noise_density = rig.gyro_noise_density;
  n.accel_noise_density = rig.accel_noise_density;
  n.gyro_random_walk = rig.gyro_random_walk;
  n.accel_random_walk = rig.accel_random_walk;
  n.gyro_scale_std = rig.gyro_scale_std;
  n.gyro_misalignment_std = rig.gyro_misalignment_std;
  return n;
}

ImuPreintegration::ImuPreintegration(const Vec3& gyro_bias, const Vec3& accel_bias, const ImuPreintegrationNoise& noise)
    : noise_(noise) {
  reset(gyro_bias, accel_bias);
}

void ImuPreintegration::reset(const Vec3& gyro_bias, const Vec3& accel_bias) {
  bg_ = gyro_bias;
  ba_ = accel_bias;
  duration_ = 0.0;
  delta_q_ = Quat::Identity();
  delta_R_ = Mat3::Identity();
  delta_v_ = Vec3::Zero();
  delta_p_ = Vec3::Zero();
  covariance_ = Mat9::Zero();
  dR_dbg_ = dV_dbg_ = dV_dba_ = dP_dbg_ = dP_dba_ = Mat3::Zero();
}

void ImuPreintegration::integrate(const Vec3& gyro, const Vec3& accel, double dt) {
  if (!std::isfinite(dt) || dt < 0.0) throw std::invalid_argument("ImuPreintegration::integrate: dt must be >= 0");
  if (dt == 0.0) return;
  const Vec3 w = gyro - bg_;
  const Vec3 a = accel - ba_;
  const Vec3 theta = w * dt;
  const Mat3 step_R = so3::Exp(theta);        // Exp(w dt)
  const Mat3 half_R = so3::Exp(0.5 * theta);  // Exp(½ w dt)
  const Mat3 Jr = so3::rightJacobian(theta);
  const Mat3 Jr_half = so3::rightJacobian(0.5 * theta);
  const Mat3 mid_R = delta_R_ * half_R;  // ΔR_m, the rotation at the interval's middle
  const Vec3 dv = mid_R * a * dt;        // velocity increment in frame i

  // Linearisation: x_{k+1} = A x_k + B n with x = [δφ, δv, δp] and n = [gyro, accel] noise.
  // ∂(ΔR_m a)/∂δφ = -ΔR_k hat(Exp(½ w dt) a); ∂(ΔR_m a)/∂n_g = -ΔR_m hat(a) Jr(½ w dt) ½ dt.
  const Mat3 dv_dphi = -delta_R_ * so3::hat(half_R * a) * dt;
  const Mat3 dv_dng = -0.5 * dt * dt * mid_R * so3::hat(a) * Jr_half;
  const Mat3 dv_dna = mid_R * dt;
  Mat9 A = Mat9::Identity();
  A.block<3, 3>(0, 0) = step_R.transpose();
  A.block<3, 3>(3, 0) = dv_dphi;
  A.block<3, 3>(6, 0) = 0.5 * dt * dv_dphi;
  A.block<3, 3>(6, 3) = Mat3::Identity() * dt;
  Eigen::Matrix<double, 9, 6> B = Eigen::Matrix<double, 9, 6>::Zero();
  B.block<3, 3>(0, 0) = Jr * dt;
  B.block<3, 3>(3, 0) = dv_dng;
  B.block<3, 3>(3, 3) = dv_dna;
  B.block<3, 3>(6, 0) = 0.5 * dt * dv_dng;
  B.block<3, 3>(6, 3) = 0.5 * dt * dv_dna;
  Eigen::Matrix<double, 6, 1> q;
  Vec3 gyro_density2 = Vec3::Constant(noise_.gyro_noise_density * noise_.gyro_noise_density);
  if (noise_.gyro_scale_std > 0.0 || noise_.gyro_misalignment_std > 0.0)
    gyro_density2 += gyroSystematicDensity2(w, noise_.gyro_scale_std, noise_.gyro_misalignment_std,
                                            noise_.systematic_error_window_s);
  q << gyro_density2 / dt, Vec3::Constant(noise_.accel_noise_density * noise_.accel_noise_density / dt);
  covariance_ = A * covariance_ * A.transpose() + B * q.asDiagonal() * B.transpose();
  covariance_ = (0.5 * (covariance_ + covariance_.transpose())).eval();  // (aliasing)

  // Bias Jacobians: a bias change δb acts as the constant noise n = -δb (old values first).
  const Mat3 dv_dbg_step = dv_dphi * dR_dbg_ - dv_dng;
  const Mat3 dv_dba_step = -dv_dna;
  dP_dbg_ += dV_dbg_ * dt + 0.5 * dt * dv_dbg_step;
  dP_dba_ += dV_dba_ * dt + 0.5 * dt * dv_dba_step;
  dV_dbg_ += dv_dbg_step;
  dV_dba_ += dv_dba_step;
  dR_dbg_ = step_R.transpose() * dR_dbg_ - Jr * dt;

  // The increments.
  delta_p_ += delta_v_ * dt + 0.5 * dt * dv;
  delta_v_ += dv;
  delta_q_ = (delta_q_ * so3::ExpQuat(theta)).normalized();
  delta_R_ = delta_q_.toRotationMatrix();
  duration_ += dt;
}

Mat6 ImuPreintegration::biasRandomWalkCovariance() const {
  Vec6 d;
  d << Vec3::Constant(noise_.gyro_random_walk * noise_.gyro_random_walk * duration_),
      Vec3::Constant(noise_.accel_random_walk * noise_.accel_random_walk * duration_);
  return d.asDiagonal();
}

Mat3 ImuPreintegration::correctedDeltaR(const Vec3& bg) const { return delta_R_ * so3::Exp(dR_dbg_ * (bg - bg_)); }

Vec3 ImuPreintegration::correctedDeltaV(const Vec3& bg, const Vec3& ba) const {
  return delta_v_ + dV_dbg_ * (bg - bg_) + dV_dba_ * (ba - ba_);
}

Vec3 ImuPreintegration::correctedDeltaP(const Vec3& bg, const Vec3& ba) const {
  return delta_p_ + dP_dbg_ * (bg - bg_) + dP_dba_ * (ba - ba_);
}

void ImuPreintegration::predict(const Mat3& R_i, const Vec3& p_i, const Vec3& v_i, const Vec3& bg, const Vec3& ba,
                                const Vec3& gravity_W, Mat3* R_j, Vec3* p_j, Vec3* v_j) const {
  const double dt = duration_;
  *R_j = so3::normalize(R_i * correctedDeltaR(bg));
  *v_j = v_i + gravity_W * dt + R_i * correctedDeltaV(bg, ba);
  *p_j = p_i + v_i * dt + 0.5 * gravity_W * dt * dt + R_i * correctedDeltaP(bg, ba);
}

Vec9 ImuPreintegration::residual(const Mat3& R_i, const Vec3& p_i, const Vec3& v_i, const Mat3& R_j, const Vec3& p_j,
                                 const Vec3& v_j, const Vec3& bg, const Vec3& ba, const Vec3& gravity_W) const {
  const double dt = duration_;
  Vec9 r;
  r.head<3>() = so3::Log(Mat3(correctedDeltaR(bg).transpose() * R_i.transpose() * R_j));
  r.segment<3>(3) = R_i.transpose() * (v_j - v_i - gravity_W * dt) - correctedDeltaV(bg, ba);
  r.tail<3>() = R_i.transpose() * (p_j - p_i - v_i * dt - 0.5 * gravity_W * dt * dt) - correctedDeltaP(bg, ba);
  return r;
}

Mat9 ImuPreintegration::sqrtInformation() const { return upperSqrtInformation(covariance_); }

}  // namespace livo
