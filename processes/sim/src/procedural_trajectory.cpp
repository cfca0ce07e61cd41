#include "livo/sim/procedural_trajectory.hpp"

#include <cmath>

namespace livo::sim {

namespace {

constexpr double kDeg = M_PI / 180.0;

Mat3 rotX(double a) { return Eigen::AngleAxisd(a, Vec3::UnitX()).toRotationMatrix(); }
Mat3 rotY(double a) { return Eigen::AngleAxisd(a, Vec3::UnitY()).toRotationMatrix(); }
Mat3 rotZ(double a) { return Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix(); }

/// d/dt of u/|u| given u and du/dt.
Vec3 normalizedRate(const Vec3& u, const Vec3& du) {
  const double n = u.norm();
  const Vec3 q = u / n;
  return (du - q * q.dot(du)) / n;
}

MotionShake scaled(MotionShake m, double scale) {
  for (auto* group : {m.position, m.attitude})
    for (int i = 0; i < 3; ++i)
      for (auto& w : group[i]) w.amplitude *= scale;
  return m;
}

}  // namespace

void sumOfSinusoids(const std::vector<Sinusoid>& waves, double s, double out[4]) {
  out[0] = out[1] = out[2] = out[3] = 0.0;
  for (const Sinusoid& w : waves) {
    const double om = 2.0 * M_PI * w.frequency_hz;
    const double sn = std::sin(om * s + w.phase), cs = std::cos(om * s + w.phase);
    out[0] += w.amplitude * sn;
    out[1] += w.amplitude * om * cs;
    out[2] -= w.amplitude * om * om * sn;
    out[3] -= w.amplitude * om * om * om * cs;
  }
}

MotionShake handheldShake(double scale) {
  MotionShake m;
  m.position[0] = {{0.008, 0.9, 0.0}, {0.003, 2.3, 1.0}};
  m.position[1] = {{0.008, 0.93, 2.0}, {0.003, 2.1, 0.5}};
  m.position[2] = {{0.020, 1.8, 0.0}, {0.005, 3.6, 1.3}};  // step bobbing
  m.attitude[0] = {{1.5 * kDeg, 0.9, 0.3}, {0.5 * kDeg, 2.7, 1.1}};
  m.attitude[1] = {{1.0 * kDeg, 1.8, 0.7}, {0.4 * kDeg, 3.1, 2.0}};
  m.attitude[2] = {{2.0 * kDeg, 0.45, 1.7}, {0.6 * kDeg, 1.9, 0.2}};
  return scaled(m, scale);
}

MotionShake carShake(double scale) {
  MotionShake m;
  m.position[2] = {{0.010, 1.3, 0.0}, {0.003, 4.7, 0.9}};  // suspension
  m.attitude[0] = {{0.3 * kDeg, 1.1, 0.4}, {0.1 * kDeg, 3.9, 1.5}};
  m.attitude[1] = {{0.4 * kDeg, 1.4, 2.2}, {0.1 * kDeg, 5.3, 0.6}};
  return scaled(m, scale);
}

MotionShake flightShake(double scale) {
  // no position shake: with a thrust-aligned attitude any position jitter turns into attitude
  // whipping through the jerk; a little attitude wobble instead
  MotionShake m;
  m.attitude[0] = {{0.4 * kDeg, 2.3, 0.3}};
  m.attitude[1] = {{0.4 * kDeg, 2.9, 1.2}};
  m.attitude[2] = {{0.3 * kDeg, 0.8, 0.0}};
  return scaled(m, scale);
}

ProceduralTrajectory::ProceduralTrajectory(std::unique_ptr<Path> path, const ProceduralTrajectoryOptions& options)
    : path_(std::move(path)), options_(options) {}

PathTimeWarp rampedPathTime(double t, double start_still_s, double ramp_s) {
  const double hold = start_still_s, ramp = ramp_s;
  if (t <= hold) return {0.0, 0.0, 0.0, 0.0};
  if (ramp > 0.0 && t < hold + ramp) {
    // s' = 35x^4 - 84x^5 + 70x^6 - 20x^7: its first three derivatives vanish at both ends, so
    // acceleration, jerk and snap (hence a thrust-aligned attitude's rate and its derivative)
    // stay continuous
    const double x = (t - hold) / ramp;
    const double x2 = x * x, x3 = x2 * x, x4 = x3 * x, x5 = x4 * x, x6 = x5 * x, x7 = x6 * x;
    return {ramp * (7.0 * x5 - 14.0 * x6 + 10.0 * x7 - 2.5 * x7 * x), 35.0 * x4 - 84.0 * x5 + 70.0 * x6 - 20.0 * x7,
            (140.0 * x3 - 420.0 * x4 + 420.0 * x5 - 140.0 * x6) / ramp,
            (420.0 * x2 - 1680.0 * x3 + 2100.0 * x4 - 840.0 * x5) / (ramp * ramp)};
  }
  return {0.5 * ramp + (t - hold - ramp), 1.0, 0.0, 0.0};
}

BodyState ProceduralTrajectory::at(double t) const {
  const PathTimeWarp w = rampedPathTime(t, options_.start_still_s, options_.ramp_s);
  const PathSample base = path_->at(w.s);

  // position with shake, derivatives in path time, then in time
  Vec3 p = base.p, p1 = base.d1, p2 = base.d2, p3 = base.d3;
  double wave[4];
  for (int i = 0; i < 3; ++i) {
    sumOfSinusoids(options_.shake.position[i], w.s, wave);
    p[i] += wave[0], p1[i] += wave[1], p2[i] += wave[2], p3[i] += wave[3];
  }
  BodyState st;
  st.velocity = p1 * w.d1;
  st.acceleration = p2 * w.d1 * w.d1 + p1 * w.d2;
  const Vec3 jerk = p3 * w.d1 * w.d1 * w.d1 + 3.0 * p2 * w.d1 * w.d2 + p1 * w.d3;

  // base attitude and its body rate
  Mat3 R_base;
  Vec3 omega_base;
  if (options_.attitude == AttitudeMode::kFollowHeading) {
    const double vx = base.d1.x(), vy = base.d1.y();
    const double yaw = std::atan2(vy, vx);
    const double yaw_rate_s = (vx * base.d2.y() - vy * base.d2.x()) / std::max(vx * vx + vy * vy, 1e-18);
    R_base = rotZ(yaw);
    omega_base = Vec3(0.0, 0.0, yaw_rate_s * w.d1);
  } else {
    double yw[4];
    sumOfSinusoids({options_.yaw_wave}, w.s, yw);
    const double yaw = options_.yaw_rate * w.s + yw[0];
    const double yaw_dot = (options_.yaw_rate + yw[1]) * w.d1;
    const Vec3 u = st.acceleration + Vec3(0.0, 0.0, options_.gravity);
    const Vec3 z = u.normalized(), dz = normalizedRate(u, jerk);
    const Vec3 xc(std::cos(yaw), std::sin(yaw), 0.0), dxc = yaw_dot * Vec3(-std::sin(yaw), std::cos(yaw), 0.0);
    const Vec3 wv = z.cross(xc), dwv = dz.cross(xc) + z.cross(dxc);
    const Vec3 y = wv.normalized(), dy = normalizedRate(wv, dwv);
    const Vec3 x = y.cross(z), dx = dy.cross(z) + y.cross(dz);
    R_base.col(0) = x, R_base.col(1) = y, R_base.col(2) = z;
    Mat3 dR;
    dR.col(0) = dx, dR.col(1) = dy, dR.col(2) = dz;
    const Mat3 A = R_base.transpose() * dR;
    omega_base = so3::vee(0.5 * (A - A.transpose()));
  }

  // attitude shake: R_pert = Rz(c) Ry(b) Rx(a)
  double ra[4], pb[4], yc[4];
  sumOfSinusoids(options_.shake.attitude[0], w.s, ra);
  sumOfSinusoids(options_.shake.attitude[1], w.s, pb);
  sumOfSinusoids(options_.shake.attitude[2], w.s, yc);
  const Mat3 Rx = rotX(ra[0]), Ry = rotY(pb[0]), Rz = rotZ(yc[0]);
  const Mat3 R_pert = Rz * Ry * Rx;
  const Vec3 omega_pert = (Rx.transpose() * Ry.transpose() * Vec3(0.0, 0.0, yc[1]) +
                           Rx.transpose() * Vec3(0.0, pb[1], 0.0) + Vec3(ra[1], 0.0, 0.0)) *
                          w.d1;

  st.T_W_I.linear() = R_base * R_pert;
  st.T_W_I.translation() = p;
  st.angular_velocity = R_pert.transpose() * omega_base + omega_pert;
  return st;
}

}  // namespace livo::sim
