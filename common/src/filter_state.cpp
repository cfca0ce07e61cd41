#include "livo/filter_state.hpp"

namespace livo {

FilterState FilterState::boxplus(const Vec18& d) const {
  FilterState out;
  out.rot = rot * so3::Exp(d.segment<3>(kRot));
  out.pos = pos + d.segment<3>(kPos);
  out.vel = vel + d.segment<3>(kVel);
  out.gyro_bias = gyro_bias + d.segment<3>(kGyroBias);
  out.accel_bias = accel_bias + d.segment<3>(kAccelBias);
  out.gravity = gravity + d.segment<3>(kGravity);
  return out;
}

Vec18 FilterState::boxminus(const FilterState& y) const {
  Vec18 d;
  d.segment<3>(kRot) = so3::Log(Mat3(y.rot.transpose() * rot));
  d.segment<3>(kPos) = pos - y.pos;
  d.segment<3>(kVel) = vel - y.vel;
  d.segment<3>(kGyroBias) = gyro_bias - y.gyro_bias;
  d.segment<3>(kAccelBias) = accel_bias - y.accel_bias;
  d.segment<3>(kGravity) = gravity - y.gravity;
  return d;
}

Mat18 FilterState::boxminusJacobian(const FilterState& x, const FilterState& y) {
  Mat18 H = Mat18::Identity();
  H.block<3, 3>(kRot, kRot) = so3::rightJacobianInverse(so3::Log(Mat3(y.rot.transpose() * x.rot)));
  return H;
}

}  // namespace livo
