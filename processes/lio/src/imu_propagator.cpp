#include "livo/lio/imu_propagator.hpp"

#include "livo/imu_preintegration.hpp"

namespace livo::lio {

namespace {
// the readings through the sensing axes (the nominal sensor: the readings themselves, exactly)
Vec3 correctedRate(const Vec3& gyro, const FilterState& x, const ImuIntrinsics& k) {
  return k.value.isZero(0.0) ? Vec3(gyro - x.gyro_bias) : k.angularVelocity(gyro, x.gyro_bias);
}
Vec3 correctedForce(const Vec3& accel, const FilterState& x, const ImuIntrinsics& k) {
  return k.value.isZero(0.0) ? Vec3(accel - x.accel_bias) : k.specificForce(accel, x.accel_bias);
}
}  // namespace

FilterState propagateState(const FilterState& x, const Vec3& gyro, const Vec3& accel, double dt,
                           const ImuIntrinsics& intrinsics) {
  // f(x, u, 0) of eq. (4), applied with ⊞ as eq. (3)/(5).
  StateVector f = StateVector::Zero();
  f.segment<3>(FilterState::kRot) = correctedRate(gyro, x, intrinsics);
  f.segment<3>(FilterState::kPos) = x.vel;
  f.segment<3>(FilterState::kVel) = x.rot * correctedForce(accel, x, intrinsics) + x.gravity;
  return x.boxplus(f * dt);
}

void propagationJacobians(const FilterState& x, const Vec3& gyro, const Vec3& accel, double dt, Mat18* Fx, Mat18x12* Fw,
                          const ImuIntrinsics& intrinsics, IntrinsicsJacobian* Fm) {
  using S = FilterState;
  const Vec3 w = correctedRate(gyro, x, intrinsics);
  const Vec3 a = correctedForce(accel, x, intrinsics);
  const Vec3 wdt = w * dt;
  const Mat3 JrDt = so3::rightJacobian(wdt) * dt;
  // the bias and the white noise are read through the axes too: ∂w/∂b_g = -K_g^-1
  const bool nominal = intrinsics.value.isZero(0.0);
  const Mat3 JrDtKg = nominal ? JrDt : Mat3(JrDt * intrinsics.gyroAxes().inverse());
  const Mat3 RDtKa = nominal ? Mat3(x.rot * dt) : Mat3(x.rot * intrinsics.accelAxes().inverse() * dt);

  Fx->setIdentity();
  Fx->block<3, 3>(S::kRot, S::kRot) = so3::Exp(-wdt);
  Fx->block<3, 3>(S::kRot, S::kGyroBias) = -JrDtKg;
  Fx->block<3, 3>(S::kPos, S::kVel) = Mat3::Identity() * dt;
  Fx->block<3, 3>(S::kVel, S::kRot) = -x.rot * so3::hat(a) * dt;
  Fx->block<3, 3>(S::kVel, S::kAccelBias) = -RDtKa;
  Fx->block<3, 3>(S::kVel, S::kGravity) = Mat3::Identity() * dt;

  Fw->setZero();
  Fw->block<3, 3>(S::kRot, 0) = -JrDtKg;
  Fw->block<3, 3>(S::kVel, 3) = -RDtKa;
  Fw->block<3, 3>(S::kGyroBias, 6) = Mat3::Identity() * dt;
  Fw->block<3, 3>(S::kAccelBias, 9) = Mat3::Identity() * dt;

  if (Fm) {
    using K = ImuIntrinsics;
    Fm->setZero();
    Fm->block<3, 9>(S::kRot, K::kGyroScale) = JrDt * K::readingJacobian(intrinsics.gyroAxes(), w);
    Fm->block<3, 9>(S::kVel, K::kAccelScale) = x.rot * dt * K::readingJacobian(intrinsics.accelAxes(), a);
  }
}

Mat12 discreteNoiseCovariance(const ImuNoise& n, double dt, const Vec3& omega) {
  Mat12 Q = Mat12::Zero();
  const double inv = 1.0 / dt;
  const Vec3 systematic =
      gyroSystematicDensity2(omega, n.gyro_scale_std, n.gyro_misalignment_std, n.systematic_error_window_s);
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
  intrinsics_cross_.setZero();
  intrinsics_clone_cross_.setZero();
  last_ = last;
  segments_.clear();
}

void ImuPropagator::setState(const FilterState& x, const StateCovariance& P) {
  x_ = x;
  P_ = P;
}

void ImuPropagator::setIntrinsics(const ImuIntrinsics& k, const ImuIntrinsics::Covariance& P, bool estimate) {
  intrinsics_ = k;
  intrinsics_cov_ = P;
  model_intrinsics_ = P.diagonal().maxCoeff() > 0.0;
  update_intrinsics_ = model_intrinsics_ && estimate;
  intrinsics_cross_.setZero();
  intrinsics_clone_cross_.setZero();
}

void ImuPropagator::clonePose() {
  clone_cross_ = P_.leftCols<6>();
  intrinsics_clone_cross_ = intrinsics_cross_.topRows<6>().transpose();
}

void ImuPropagator::applyUpdate(const FilterState& x, const StateCovariance& P) {
  if (!model_intrinsics_) {
    clone_cross_ = carriedThroughUpdate(P_, P, clone_cross_);
  } else {
    constexpr int k = ImuIntrinsics::kDim;
    Eigen::MatrixXd C(FilterState::kDim, k + 6);
    C << intrinsics_cross_, clone_cross_;
    const ConditionedBeside r = conditionedOnUpdate(P_, P, C, x.boxminus(x_));
    intrinsics_cross_ = r.cross.leftCols<k>();
    clone_cross_ = r.cross.rightCols<6>();
    if (update_intrinsics_) {  // estimated (considered, their value and covariance stay)
      intrinsics_.value += r.mean_step.head<k>();
      const ImuIntrinsics::Covariance Pk = intrinsics_cov_ + r.covariance_change.topLeftCorner<k, k>();
      intrinsics_cov_ = 0.5 * (Pk + Pk.transpose());
      // the clone is only considered: its own covariance stays, its cross with the intrinsics moves
      intrinsics_clone_cross_ += r.covariance_change.topRightCorner<k, 6>();
    }
  }
  x_ = x;
  P_ = P;
}

void ImuPropagator::changeFrame(const FilterState& x, const StateCovariance& T, const Mat6& Tc) {
  x_ = x;
  P_ = T * P_ * T.transpose();
  clone_cross_ = T * clone_cross_ * Tc.transpose();
  intrinsics_cross_ = T * intrinsics_cross_;
  intrinsics_clone_cross_ = intrinsics_clone_cross_ * Tc.transpose();
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
  seg.omega = correctedRate(gyro, x_, intrinsics_);
  seg.acc_world = x_.rot * correctedForce(accel, x_, intrinsics_) + x_.gravity;
  segments_.push_back(seg);

  if (dt > 0.0) {
    Mat18 Fx;
    Mat18x12 Fw;
    IntrinsicsJacobian Fm;
    propagationJacobians(x_, gyro, accel, dt, &Fx, &Fw, intrinsics_, model_intrinsics_ ? &Fm : nullptr);
    x_ = propagateState(x_, gyro, accel, dt, intrinsics_);
    // [A B; B^T C] -> [F A F^T + Fw Q Fw^T, F B; (F B)^T, C]: the calibration is constant. The
    // budget for the gyro's axis errors (discreteNoiseCovariance) is left out when they are states.
    constexpr int n = FilterState::kNavDim, c = FilterState::kDim - FilterState::kNavDim;
    const Mat12 Q = discreteNoiseCovariance(noise_, dt, model_intrinsics_ ? Vec3::Zero() : seg.omega);
    Mat18 A = Fx * P_.topLeftCorner<n, n>() * Fx.transpose() + Fw * Q * Fw.transpose();
    Eigen::Matrix<double, n, c> B = Fx * P_.topRightCorner<n, c>();
    if (model_intrinsics_) {
      // the navigation state also moves with the intrinsics k: x' = Fx x + Fm k
      const Eigen::Matrix<double, n, ImuIntrinsics::kDim> Xn = intrinsics_cross_.topRows<n>();
      const Mat18 FXF = Fx * Xn * Fm.transpose();
      A += FXF + FXF.transpose() + Fm * intrinsics_cov_ * Fm.transpose();
      B += Fm * intrinsics_cross_.bottomRows<c>().transpose();
      intrinsics_cross_.topRows<n>() = Fx * Xn + Fm * intrinsics_cov_;
      clone_cross_.topRows<n>() = (Fx * clone_cross_.topRows<n>() + Fm * intrinsics_clone_cross_).eval();
    } else {
      clone_cross_.topRows<n>() = (Fx * clone_cross_.topRows<n>()).eval();
    }
    P_.topLeftCorner<n, n>() = 0.5 * (A + A.transpose());
    P_.topRightCorner<n, c>() = B;
    P_.bottomLeftCorner<c, n>() = B.transpose();
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
