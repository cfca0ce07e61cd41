#include "livo/vio/rolling_shutter.hpp"

namespace livo::vio {

namespace {
constexpr int kFixedPointSteps = 2;
}

RollingShutter RollingShutter::fromReadout(double readout_s, int rows) {
  RollingShutter s;
  s.line_time = rows > 0 ? readout_s / rows : 0.0;
  s.centre_row = 0.5 * (rows - 1);
  return s;
}

Mat3 RollingShutter::rotationSince(double dt) const { return so3::Exp(omega_I * dt); }

bool projectThroughShutter(const CameraProjection& camera, const Pose3& T_I_C, const FilterState& x,
                           const RollingShutter& shutter, const Vec3& p_W, ShutterProjection* out, double border,
                           bool with_jacobian) {
  const Pose3 T_C_I = T_I_C.inverse();
  out->dt = 0.0;
  out->R_W_I = x.rot;
  out->p_W_I = x.pos;
  const int steps = shutter.active() ? kFixedPointSteps : 0;
  for (int k = 0;; ++k) {
    out->p_I = out->R_W_I.transpose() * (p_W - out->p_W_I);
    out->p_C = T_C_I * out->p_I;
    const bool projects = with_jacobian ? camera.projectWithJacobian(out->p_C, &out->pixel, &out->J_proj)
                                        : camera.project(out->p_C, &out->pixel);
    if (!projects) return false;
    if (k == steps) break;
    out->dt = shutter.rowTime(out->pixel.y());
    out->R_W_I = x.rot * shutter.rotationSince(out->dt);
    out->p_W_I = x.pos + x.vel * out->dt;
  }
  const double w = camera.rig().width, h = camera.rig().height;
  const Eigen::Vector2d& u = out->pixel;
  return u.x() >= border && u.y() >= border && u.x() <= w - 1.0 - border && u.y() <= h - 1.0 - border;
}

FilterState advanced(const FilterState& x, const Vec3& omega_I, double dt) {
  if (dt == 0.0) return x;
  FilterState y = x;
  y.rot = x.rot * so3::Exp(omega_I * dt);
  y.pos = x.pos + x.vel * dt;
  return y;
}

Pose3 cameraPoseAt(const FilterState& x, const RollingShutter& shutter, double dt, const Pose3& T_I_C) {
  return se3::fromRotationTranslation(x.rot * shutter.rotationSince(dt), x.pos + x.vel * dt) * T_I_C;
}

}  // namespace livo::vio
