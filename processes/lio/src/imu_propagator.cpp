#include "livo/lio/imu_propagator.hpp"

namespace livo::lio {

FilterState propagateState(const FilterState& x, const Vec3& gyro, const Vec3& accel, double dt) {
  // f(x, u, 0) of eq. (4), applied with ⊞ as eq. (3)/(5).
  StateVector f = StateVector::Zero();
  f.segment<3>(FilterState::kRot) = gyro - x.gyro_bias;
  f.segment<3>(FilterState::kPos) = x.vel;
  f.segment<3>(FilterState::kVel) = x.rot * (accel - x.accel_bias) + x.gravity;
  return x.boxplus(f * dt);
}

void propagationJacobians(const FilterState& x, const Vec3& gyro, const Vec3& accel, double dt, Mat18* Fx,
                          Mat18x12* Fw) {
  using S = FilterState;
  const Vec3 w = gyro - x.gyro_bias;
  const Vec3 a = accel - x.accel_bias;
  const Vec3 wdt = w * dt;
  const Mat3 JrDt = so3::rightJacobian(wdt) * dt;

  Fx->setIdentity();
  Fx->block<3, 3>(S::kRot, S::kRot) = so3::Exp(-wdt);
  Fx->block<3, 3>(S::kRot, S::kGyroBias) = -JrDt;
  Fx->block<3, 3>(S::kPos, S::kVel) = Mat3::Identity() * dt;
  Fx->block<3, 3>(S::kVel, S::kRot) = -x.rot * so3::hat(a) * dt;
  Fx->block<3, 3>(S::kVel, S::kAccelBias) = -x.rot * dt;
  Fx->block<3, 3>(S::kVel, S::kGravity) = Mat3::Identity() * dt;

  Fw->setZero();
  Fw->block<3, 3>(S::kRot, 0) = -JrDt;
  Fw->block<3, 3>(S::kVel, 3) = -x.rot * dt;
  Fw->block<3, 3>(S::kGyroBias, 6) = Mat3::Identity() * dt;
  Fw->block<3, 3>(S::kAccelBias, 9) = Mat3::Identity() * dt;
}

Mat12 discreteNoiseCovariance(const ImuNoise& n, double dt, const Vec3& omega) {
  Mat12 Q = Mat12::Zero();
  const double inv = 1.0 / dt;
  // var((M w)_i) = s^2 w_i^2 + m^2 (|w|^2 - w_i^2) for M = I + scale + misalignment with independent entries
  const Vec3 w2 = omega.cwiseAbs2();
  const double s2 = n.gyro_scale_std * n.gyro_scale_std, m2 = n.gyro_misalignment_std * n.gyro_misalignment_std;
  const Vec3 systematic = (s2 * w2 + m2 * (Vec3::Constant(w2.sum()) - w2)) * n.systematic_error_window_s;
  Q.diagonal().segment<3>(0) = (Vec3::Constant(n.gyro_noise_density * n.gyro_noise_density) + systematic) * inv;
  Q.diagonal().segment<3>(3).setConstant(n.accel_noise_density * n.accel_noise_density * inv);
  Q.diagonal().segment<3>(6).setConstant(n.gyro_random_walk * n.gyro_random_walk * inv);
  Q.diagonal().segment<3>(9).setConstant(n.accel_random_walk * n.accel_random_walk * inv);
  return Q;
}

void ImuPropagator::reset(const FilterState& x, const StateCovariance& P, const ImuSample& last) {
  x_ = x;
  P_ = P;
  clone_cross_.setZero();
  last_ = last;
  segments_.clear();
}

void ImuPropagator::setState(const FilterState& x, const StateCovariance& P) {
  x_ = x;
  P_ = P;
}

void ImuPropagator::step(const ImuSample& next) {
  const double dt = static_cast<double>(next.utime - last_.utime) * 1e-6;
  const Vec3 gyro = 0.5 * (last_.gyro + next.gyro);
  const Vec3 accel = 0.5 * (last_.accel + next.accel);

  ImuSegment seg;
  seg.utime = last_.utime;
  seg.rot = x_.rot;
  seg.pos = x_.pos;
  seg.vel = x_.vel;
  seg.omega = gyro - x_.gyro_bias;
  seg.acc_world = x_.rot * (accel - x_.accel_bias) + x_.gravity;
  segments_.push_back(seg);

  if (dt > 0.0) {
    Mat18 Fx;
    Mat18x12 Fw;
    propagationJacobians(x_, gyro, accel, dt, &Fx, &Fw);
    x_ = propagateState(x_, gyro, accel, dt);
    // [A B; B^T C] -> [F A F^T + Fw Q Fw^T, F B; (F B)^T, C]: the calibration is constant
    constexpr int n = FilterState::kNavDim, c = FilterState::kDim - FilterState::kNavDim;
    Mat18 A = Fx * P_.topLeftCorner<n, n>() * Fx.transpose() +
              Fw * discreteNoiseCovariance(noise_, dt, seg.omega) * Fw.transpose();
    P_.topLeftCorner<n, n>() = 0.5 * (A + A.transpose());
    const Eigen::Matrix<double, n, c> B = Fx * P_.topRightCorner<n, c>();
    P_.topRightCorner<n, c>() = B;
    P_.bottomLeftCorner<c, n>() = B.transpose();
    clone_cross_.topRows<n>() = (Fx * clone_cross_.topRows<n>()).eval();
  }
  last_ = next;
}

bool ImuPropagator::addSample(const ImuSample& s) {
  if (s.utime <= last_.utime) return false;
  step(s);
  return true;
}

void ImuPropagator::propagateTo(int64_t utime, const ImuSample& next) {
  if (utime <= last_.utime) return;
  ImuSample at;
  at.utime = utime;
  if (next.utime > last_.utime && next.utime >= utime) {
    const double alpha = static_cast<double>(utime - last_.utime) / static_cast<double>(next.utime - last_.utime);
    at.gyro = (1.0 - alpha) * last_.gyro + alpha * next.gyro;
    at.accel = (1.0 - alpha) * last_.accel + alpha * next.accel;
  } else {
    at.gyro = last_.gyro;
    at.accel = last_.accel;
  }
  step(at);
}

void ImuPropagator::transformSegments(const Pose3& T) {
  const Mat3 R = T.linear();
  for (ImuSegment& g : segments_) {
    g.rot = so3::normalize(R * g.rot);
    g.pos = R * g.pos + T.translation();
    g.vel = R * g.vel;
    g.acc_world = R * g.acc_world;
  }
}

void ImuPropagator::dropSegmentsBefore(int64_t utime) {
  // segment k lasts until segment k + 1 starts (the last one until utime())
  size_t keep = 0;
  while (keep + 1 < segments_.size() && segments_[keep + 1].utime <= utime) ++keep;
  segments_.erase(segments_.begin(), segments_.begin() + static_cast<std::ptrdiff_t>(keep));
}

}  // namespace livo::lio
