#include "livo/filter_state.hpp"

#include <Eigen/Cholesky>

namespace livo {

namespace {
SensorCalibration plus(const SensorCalibration& c, const StateVector& d, int block) {
  SensorCalibration out;
  out.rot = c.rot * so3::Exp(d.segment<3>(block + FilterState::kCalRot));
  out.pos = c.pos + d.segment<3>(block + FilterState::kCalPos);
  out.dt = c.dt + d[block + FilterState::kCalDt];
  return out;
}

void minus(const SensorCalibration& a, const SensorCalibration& b, int block, StateVector* d) {
  d->segment<3>(block + FilterState::kCalRot) = so3::Log(Mat3(b.rot.transpose() * a.rot));
  d->segment<3>(block + FilterState::kCalPos) = a.pos - b.pos;
  (*d)[block + FilterState::kCalDt] = a.dt - b.dt;
}
}  // namespace

FilterState FilterState::boxplus(const StateVector& d) const {
  FilterState out;
  out.rot = rot * so3::Exp(d.segment<3>(kRot));
  out.pos = pos + d.segment<3>(kPos);
  out.vel = vel + d.segment<3>(kVel);
  out.gyro_bias = gyro_bias + d.segment<3>(kGyroBias);
  out.accel_bias = accel_bias + d.segment<3>(kAccelBias);
  out.gravity = gravity + d.segment<3>(kGravity);
  out.lidar = plus(lidar, d, kLidar);
  out.camera = plus(camera, d, kCamera);
  return out;
}

StateVector FilterState::boxminus(const FilterState& y) const {
  StateVector d;
  d.segment<3>(kRot) = so3::Log(Mat3(y.rot.transpose() * rot));
  d.segment<3>(kPos) = pos - y.pos;
  d.segment<3>(kVel) = vel - y.vel;
  d.segment<3>(kGyroBias) = gyro_bias - y.gyro_bias;
  d.segment<3>(kAccelBias) = accel_bias - y.accel_bias;
  d.segment<3>(kGravity) = gravity - y.gravity;
  minus(lidar, y.lidar, kLidar, &d);
  minus(camera, y.camera, kCamera, &d);
  return d;
}

StateCovariance FilterState::boxminusJacobian(const FilterState& x, const FilterState& y) {
  StateCovariance H = StateCovariance::Identity();
  const StateVector e = x.boxminus(y);
  for (const int b : kRotationBlocks) H.block<3, 3>(b, b) = so3::rightJacobianInverse(e.segment<3>(b));
  return H;
}

bool isUsableCovariance(const StateCovariance& P) {
  if (!P.allFinite()) return false;
  const double scale = std::max(1e-300, P.diagonal().cwiseAbs().maxCoeff());
  if ((P - P.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) return false;
  // the estimated states: a positive variance; the fixed ones: nothing at all
  int idx[FilterState::kDim];
  int n = 0;
  for (int i = 0; i < FilterState::kDim; ++i) {
    if (P(i, i) > 0.0) {
      idx[n++] = i;
    } else if (P(i, i) < 0.0 || P.row(i).cwiseAbs().maxCoeff() != 0.0) {
      return false;
    }
  }
  Eigen::MatrixXd A(n, n);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) A(r, c) = 0.5 * (P(idx[r], idx[c]) + P(idx[c], idx[r]));
  return Eigen::LLT<Eigen::MatrixXd>(A).info() == Eigen::Success;
}

void setCalibrationPrior(int block, const CalibrationStd& s, StateCovariance* P) {
  P->middleRows<FilterState::kCalibrationDim>(block).setZero();
  P->middleCols<FilterState::kCalibrationDim>(block).setZero();
  for (int i = 0; i < 3; ++i) {
    (*P)(block + FilterState::kCalRot + i, block + FilterState::kCalRot + i) = s.rotation * s.rotation;
    (*P)(block + FilterState::kCalPos + i, block + FilterState::kCalPos + i) = s.translation * s.translation;
  }
  (*P)(block + FilterState::kCalDt, block + FilterState::kCalDt) = s.time * s.time;
}

}  // namespace livo
