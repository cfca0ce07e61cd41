#include "livo/imu_initializer.hpp"

#include <cmath>

namespace livo {

namespace {
struct Moments {
  Vec3 mean_gyro = Vec3::Zero(), mean_accel = Vec3::Zero();
  Vec3 var_gyro = Vec3::Zero(), var_accel = Vec3::Zero();
};

Moments moments(const std::vector<ImuSample>& w) {
  Moments m;
  const double n = static_cast<double>(w.size());
  for (const auto& s : w) {
    m.mean_gyro += s.gyro / n;
    m.mean_accel += s.accel / n;
  }
  for (const auto& s : w) {
    m.var_gyro += (s.gyro - m.mean_gyro).cwiseAbs2() / n;
    m.var_accel += (s.accel - m.mean_accel).cwiseAbs2() / n;
  }
  return m;
}
}  // namespace

bool isStill(const std::vector<ImuSample>& window, const ImuInitOptions& opts) {
  if (window.size() < 2) return false;
  const Moments m = moments(window);
  return m.var_gyro.maxCoeff() <= opts.max_gyro_std * opts.max_gyro_std &&
         m.var_accel.maxCoeff() <= opts.max_accel_std * opts.max_accel_std;
}

ImuInitResult initializeImu(const std::vector<ImuSample>& window, const ImuInitOptions& opts) {
  using S = FilterState;
  ImuInitResult r;
  if (window.empty()) {
    r.message = "no IMU samples";
    return r;
  }
  const Moments m = moments(window);
  if (!m.mean_accel.allFinite() || m.mean_accel.norm() < 0.5 * opts.gravity) {
    r.message = "mean specific force too small for a gravity direction";
    return r;
  }
  const bool still = isStill(window, opts);
  bool use_static = false;
  switch (opts.mode) {
    case ImuInitOptions::Mode::kStatic:
      if (!still) {
        r.message = "static initialisation requested but the IMU is moving";
        return r;
      }
      use_static = true;
      break;
    case ImuInitOptions::Mode::kMoving: use_static = false; break;
    case ImuInitOptions::Mode::kAuto: use_static = still; break;
  }

  // W_R_I maps the measured "up" (specific force at rest) onto +z; the minimal such rotation.
  const Vec3 up_body = m.mean_accel.normalized();
  const Mat3 R0 = Quat::FromTwoVectors(up_body, Vec3::UnitZ()).toRotationMatrix();

  r.state = FilterState();
  r.state.rot = R0;
  r.state.gravity = Vec3(0.0, 0.0, -opts.gravity);
  r.state.gyro_bias = use_static ? m.mean_gyro : Vec3::Zero();

  auto var = [](double s) { return s * s; };
  Vec18 d;
  const double rot_std = use_static ? opts.static_rot_std : opts.moving_rot_std;
  d.segment<3>(S::kRot) = Vec3(var(rot_std), var(rot_std), var(opts.yaw_std));
  d.segment<3>(S::kPos).setConstant(var(opts.pos_std));
  d.segment<3>(S::kVel).setConstant(var(use_static ? opts.static_vel_std : opts.moving_vel_std));
  if (use_static) {
    // standard error of the mean, floored so the bias can still move
    const double n = static_cast<double>(window.size());
    for (int i = 0; i < 3; ++i) d[S::kGyroBias + i] = m.var_gyro[i] / n + var(1e-3);
  } else {
    d.segment<3>(S::kGyroBias).setConstant(var(opts.moving_gyro_bias_std));
  }
  d.segment<3>(S::kAccelBias).setConstant(var(opts.accel_bias_std));
  d.segment<3>(S::kGravity).setConstant(var(use_static ? opts.gravity_std : opts.moving_gravity_std));
  // The rotation covariance above is in the gravity-aligned frame; the state's rotation error is
  // a right (body) perturbation: δr_body = R0^T δr_world.
  Mat18 P = d.asDiagonal();
  P.block<3, 3>(S::kRot, S::kRot) = R0.transpose() * P.block<3, 3>(S::kRot, S::kRot) * R0;
  if (use_static) {
    // At rest the specific force is gravity, whose magnitude the rig states: what the mean exceeds
    // it by is the accelerometer's error along up (body frame). Across up the error is a tilt.
    const double n = static_cast<double>(window.size());
    const double up_var = up_body.dot(m.var_accel.cwiseProduct(up_body)) / n + var(opts.static_up_bias_floor);
    r.state.accel_bias = (m.mean_accel.norm() - opts.gravity) * up_body;
    P.block<3, 3>(S::kAccelBias, S::kAccelBias) = var(opts.accel_bias_std) * Mat3::Identity() +
                                                  (up_var - var(opts.accel_bias_std)) * up_body * up_body.transpose();
  }
  r.covariance = P;
  r.last = window.back();
  r.static_start = use_static;
  r.ok = true;
  r.message = use_static ? "static start" : "moving start";
  return r;
}

}  // namespace livo
