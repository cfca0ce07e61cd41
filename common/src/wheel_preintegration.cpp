#include "livo/wheel_preintegration.hpp"

#include <stdexcept>

#include "livo/text_format.hpp"

namespace livo {

std::string wheelMountingText(const Vec3& mounting) {
  const Vec3 deg = mounting * (180.0 / M_PI);
  return "wheel mounting off the rig's by roll " + formatSignificant(deg.x()) + ", pitch " +
         formatSignificant(deg.y()) + ", yaw " + formatSignificant(deg.z()) + " deg";
}

std::string wheelFactorText(const WheelRig& rig, double scale_std) {
  std::string s = "wheel preintegration";
  if (scale_std > 0.0) s += " (tyre scales estimated, prior sigma " + formatSignificant(scale_std) + ")";
  if (rig.estimatesMounting())
    s += " through the estimated mounting rotation (prior sigma " +
         formatSignificant(rig.calibration_std.rotation_deg) + " deg)";
  return s;
}

WheelPreintegrationNoise WheelPreintegrationNoise::fromRig(const WheelRig& rig) {
  WheelPreintegrationNoise n;
  n.speed_std = rig.speed_noise_std;
  return n;
}

WheelPreintegration::WheelPreintegration(const WheelRig& rig, const WheelPreintegrationNoise& noise)
    : track_width_(rig.track_width),
      rate_hz_(rig.rate_hz),
      q_IB_(Quat(rig.T_I_B.linear()).normalized()),
      t_IB_(rig.T_I_B.translation()),
      noise_(noise) {}

void WheelPreintegration::integrate(double v_left0, double v_right0, double v_left1, double v_right1, double dt) {
  if (!std::isfinite(dt) || dt < 0.0) throw std::invalid_argument("WheelPreintegration::integrate: dt must be >= 0");
  if (dt == 0.0) return;
  const double v_left = 0.5 * (v_left0 + v_left1);
  const double v_right = 0.5 * (v_right0 + v_right1);
  const Vec3 rate(0.0, 0.0, (v_right - v_left) / track_width_);
  const Vec3 step_p(0.5 * (v_left + v_right) * dt, 0.0, 0.0);
  const Vec3 theta = rate * dt;
  const Mat3 step_R = so3::Exp(theta);
  const Mat3 half_R = so3::Exp(0.5 * theta);
  const Mat3 mid_R = delta_R_ * half_R;

  // Linearisation: x_{k+1} = A x_k + B n with x = [δθ, δp] and n = [body rate, velocity] noise in O.
  Mat6 A = Mat6::Identity();
  A.block<3, 3>(0, 0) = step_R.transpose();
  A.block<3, 3>(3, 0) = -delta_R_ * so3::hat(half_R * step_p);
  Mat6 B = Mat6::Zero();
  B.block<3, 3>(0, 0) = so3::rightJacobian(theta) * dt;
  B.block<3, 3>(3, 0) = -0.5 * dt * mid_R * so3::hat(step_p) * so3::rightJacobian(0.5 * theta);
  B.block<3, 3>(3, 3) = mid_R * dt;
  // Per-reading variances scaled to the interval; the wheels' noise is independent, so forward
  // speed (v_l + v_r)/2 and yaw rate (v_r - v_l)/b are uncorrelated.
  const double scale = 1.0 / (rate_hz_ * dt);
  const double s2 = noise_.speed_std * noise_.speed_std;
  const double rp2 = noise_.roll_pitch_rate_std * noise_.roll_pitch_rate_std;
  Vec6 q;
  q << rp2, rp2, 2.0 * s2 / (track_width_ * track_width_), 0.5 * s2,
      noise_.lateral_speed_std * noise_.lateral_speed_std, noise_.vertical_speed_std * noise_.vertical_speed_std;
  covariance_ = A * covariance_ * A.transpose() + B * (scale * q).asDiagonal() * B.transpose();
  covariance_ = (0.5 * (covariance_ + covariance_.transpose())).eval();  // (aliasing)

  // Scale Jacobians: v = v0 + [v_l, v_r]/2 δs and w = w0 + [-v_l, v_r]/b δs about z; the step
  // ΔR_k Exp(J_R δs) Exp(½θ + ½ dθ) (u + du) moves Δp by -mid_R [u]x (half_R^T J_R δs + Jr(½θ) ½ dθ) + mid_R du.
  Eigen::Matrix<double, 3, 2> dtheta_ds = Eigen::Matrix<double, 3, 2>::Zero();
  dtheta_ds.row(2) << -v_left / track_width_ * dt, v_right / track_width_ * dt;
  Eigen::Matrix<double, 3, 2> du_ds = Eigen::Matrix<double, 3, 2>::Zero();
  du_ds.row(0) << 0.5 * v_left * dt, 0.5 * v_right * dt;
  dp_ds_ +=
      -mid_R * so3::hat(step_p) * (half_R.transpose() * dR_ds_ + 0.5 * so3::rightJacobian(0.5 * theta) * dtheta_ds) +
      mid_R * du_ds;
  dR_ds_ = step_R.transpose() * dR_ds_ + so3::rightJacobian(theta) * dtheta_ds;

  delta_p_ += mid_R * step_p;
  delta_q_ = (delta_q_ * so3::ExpQuat(theta)).normalized();
  delta_R_ = delta_q_.toRotationMatrix();
  duration_ += dt;
}

Mat6 WheelPreintegration::sqrtInformation() const { return upperSqrtInformation(covariance_); }

Vec6 WheelPreintegration::residual(const Mat3& R_i, const Vec3& p_i, const Mat3& R_j, const Vec3& p_j) const {
  const Mat3 R_IB = q_IB_.toRotationMatrix();
  const Mat3 R_Oi = R_i * R_IB, R_Oj = R_j * R_IB;
  const Vec3 p_Oi = p_i + R_i * t_IB_, p_Oj = p_j + R_j * t_IB_;
  Vec6 r;
  r.head<3>() = so3::Log(Mat3(delta_R_.transpose() * R_Oi.transpose() * R_Oj));
  r.tail<3>() = R_Oi.transpose() * (p_Oj - p_Oi) - delta_p_;
  return r;
}

}  // namespace livo
