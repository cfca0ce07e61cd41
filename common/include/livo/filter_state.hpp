// The ESIKF state on M = SO(3) x R^15 (paper eq. 4) with the ⊞ / ⊟ operators of eq. (1)-(2).
#pragma once

#include "livo/so3.hpp"

namespace livo {

using Vec18 = Eigen::Matrix<double, 18, 1>;
using Mat18 = Eigen::Matrix<double, 18, 18>;

struct FilterState {
  static constexpr int kDim = 18;
  // Offsets of each block in the 18-dimensional error state.
  static constexpr int kRot = 0;
  static constexpr int kPos = 3;
  static constexpr int kVel = 6;
  static constexpr int kGyroBias = 9;
  static constexpr int kAccelBias = 12;
  static constexpr int kGravity = 15;

  Mat3 rot = Mat3::Identity();   // W_R_I
  Vec3 pos = Vec3::Zero();       // W_p_I
  Vec3 vel = Vec3::Zero();       // W_v_I
  Vec3 gyro_bias = Vec3::Zero();
  Vec3 accel_bias = Vec3::Zero();
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);

  /// x ⊞ d: R Exp(d_rot), the rest added.
  FilterState boxplus(const Vec18& d) const;
  /// x ⊟ y: [Log(y.R^T x.R); x.rest - y.rest].
  Vec18 boxminus(const FilterState& y) const;

  /// H = ∂((x ⊞ d) ⊟ y) / ∂d at d = 0 (paper eq. 12): JrInv(x ⊟ y) on the rotation block,
  /// identity elsewhere.
  static Mat18 boxminusJacobian(const FilterState& x, const FilterState& y);

  Pose3 pose() const { return se3::fromRotationTranslation(rot, pos); }
};

}  // namespace livo
