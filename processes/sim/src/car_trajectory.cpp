#include "livo/sim/car_trajectory.hpp"

#include <algorithm>
#include <cmath>

namespace livo::sim {

namespace {

/// A rotation and its first two time derivatives.
struct RotationJet {
  Mat3 R, dR, ddR;
};

/// Rotation by angle a(t) about a fixed unit axis, given a, da/dt and d2a/dt2.
RotationJet axisRotation(const Vec3& axis, double a, double da, double dda) {
  const Mat3 R = Eigen::AngleAxisd(a, axis).toRotationMatrix();
  const Mat3 K = so3::hat(axis);
  return {R, R * K * da, R * (K * dda + K * K * (da * da))};
}

/// (A B), (A B)', (A B)''.
RotationJet compose(const RotationJet& a, const RotationJet& b) {
  return {a.R * b.R, a.dR * b.R + a.R * b.dR, a.ddR * b.R + 2.0 * a.dR * b.dR + a.R * b.ddR};
}

/// Heading of the path's horizontal tangent and its first two derivatives in path time.
void headingOf(const PathSample& p, double out[3]) {
  const double x1 = p.d1.x(), y1 = p.d1.y();
  const double n = x1 * p.d2.y() - y1 * p.d2.x(), dn = x1 * p.d3.y() - y1 * p.d3.x();
  const double d = std::max(x1 * x1 + y1 * y1, 1e-18), dd = 2.0 * (x1 * p.d2.x() + y1 * p.d2.y());
  out[0] = std::atan2(y1, x1);
  out[1] = n / d;
  out[2] = (dn * d - n * dd) / (d * d);
}

/// An angle f(s) with derivatives in path time, as a function of time through the warp.
void inTime(const double f[4], const PathTimeWarp& w, double* a, double* da, double* dda) {
  *a = f[0];
  *da = f[1] * w.d1;
  *dda = f[2] * w.d1 * w.d1 + f[1] * w.d2;
}

}  // namespace

CarTrajectory::CarTrajectory(std::unique_ptr<Path> path, const CarTrajectoryOptions& options)
    : path_(std::move(path)), options_(options), p_BI_(options.T_I_B.inverse().translation()) {}

BodyState CarTrajectory::at(double t) const {
  const PathTimeWarp w = rampedPathTime(t, options_.start_still_s, options_.ramp_s);
  const PathSample base = path_->at(w.s);

  // rear-axle point A: the path, lowered by the body origin's height above the axle, plus shake
  Vec3 a = base.p - Vec3(0.0, 0.0, p_BI_.z()), a1 = base.d1, a2 = base.d2;
  double wave[4];
  for (int i = 0; i < 3; ++i) {
    sumOfSinusoids(options_.shake.position[i], w.s, wave);
    a[i] += wave[0], a1[i] += wave[1], a2[i] += wave[2];
  }
  const Vec3 v_A = a1 * w.d1, acc_A = a2 * w.d1 * w.d1 + a1 * w.d2;

  // car attitude R_WB = Rz(heading + yaw shake) Ry(pitch shake) Rx(roll shake)
  double heading[3], roll[4], pitch[4], yaw[4];
  headingOf(base, heading);
  sumOfSinusoids(options_.shake.attitude[0], w.s, roll);
  sumOfSinusoids(options_.shake.attitude[1], w.s, pitch);
  sumOfSinusoids(options_.shake.attitude[2], w.s, yaw);
  for (int k = 0; k < 3; ++k) yaw[k] += heading[k];
  double ang, dang, ddang;
  inTime(yaw, w, &ang, &dang, &ddang);
  RotationJet R_WB = axisRotation(Vec3::UnitZ(), ang, dang, ddang);
  inTime(pitch, w, &ang, &dang, &ddang);
  R_WB = compose(R_WB, axisRotation(Vec3::UnitY(), ang, dang, ddang));
  inTime(roll, w, &ang, &dang, &ddang);
  R_WB = compose(R_WB, axisRotation(Vec3::UnitX(), ang, dang, ddang));

  // the body origin rides on the car: p_I = A + R_WB p_BI
  const Mat3 R_BI = options_.T_I_B.linear().transpose();
  const Mat3 A = R_WB.R.transpose() * R_WB.dR;
  const Vec3 omega_B = so3::vee(0.5 * (A - A.transpose()));
  BodyState st;
  st.T_W_I.linear() = R_WB.R * R_BI;
  st.T_W_I.translation() = a + R_WB.R * p_BI_;
  st.velocity = v_A + R_WB.dR * p_BI_;
  st.acceleration = acc_A + R_WB.ddR * p_BI_;
  st.angular_velocity = R_BI.transpose() * omega_B;
  return st;
}

}  // namespace livo::sim
