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

/// A scalar function of path time and its first two derivatives.
struct Jet {
  double f = 0.0, d1 = 0.0, d2 = 0.0;
};
Jet operator+(const Jet& a, const Jet& b) { return {a.f + b.f, a.d1 + b.d1, a.d2 + b.d2}; }
Jet operator-(const Jet& a, const Jet& b) { return {a.f - b.f, a.d1 - b.d1, a.d2 - b.d2}; }
Jet operator*(double k, const Jet& a) { return {k * a.f, k * a.d1, k * a.d2}; }
Jet operator*(const Jet& a, const Jet& b) {
  return {a.f * b.f, a.d1 * b.f + a.f * b.d1, a.d2 * b.f + 2.0 * a.d1 * b.d1 + a.f * b.d2};
}
Jet atanOf(const Jet& q) {
  const double n = 1.0 + q.f * q.f;
  return {std::atan(q.f), q.d1 / n, (q.d2 * n - 2.0 * q.f * q.d1 * q.d1) / (n * n)};
}
Jet cosOf(const Jet& a) {
  const double c = std::cos(a.f), s = std::sin(a.f);
  return {c, -s * a.d1, -c * a.d1 * a.d1 - s * a.d2};
}
/// The jet in time through the warp.
Jet inTime(const Jet& f, const PathTimeWarp& w) { return {f.f, f.d1 * w.d1, f.d2 * w.d1 * w.d1 + f.d1 * w.d2}; }

/// The ground's height under the point `ahead` metres forward and `left` metres to the left of the
/// path point, on the horizontal axes of the path's heading.
Jet groundUnder(const Terrain& ground, const PathSample& base, const double heading[3], double ahead, double left) {
  const double c = std::cos(heading[0]), s = std::sin(heading[0]), h1 = heading[1], h2 = heading[2];
  const Vec2 u(c, s), l(-s, c);
  const Vec2 u1 = h1 * l, l1 = -h1 * u;
  const Vec2 u2 = h2 * l - h1 * h1 * u, l2 = -h2 * u - h1 * h1 * l;
  const Vec2 q = base.p.head<2>() + ahead * u + left * l;
  const Vec2 q1 = base.d1.head<2>() + ahead * u1 + left * l1;
  const Vec2 q2 = base.d2.head<2>() + ahead * u2 + left * l2;
  const GroundJet g = ground.at(q.x(), q.y());
  return {g.height, g.gradient.dot(q1), q1.dot(g.hessian * q1) + g.gradient.dot(q2)};
}

}  // namespace

CarTrajectory::CarTrajectory(std::unique_ptr<Path> path, const CarTrajectoryOptions& options)
    : path_(std::move(path)), options_(options), p_BI_(options.T_I_B.inverse().translation()) {}

CarFrame CarTrajectory::frame(double t) const { return options_.ground ? gradedFrame(t) : levelFrame(t); }

CarFrame CarTrajectory::levelFrame(double t) const {
  const PathTimeWarp w = rampedPathTime(t, options_.start_still_s, options_.ramp_s);
  const PathSample base = path_->at(w.s);

  // rear-axle point A: the path, lowered by the body origin's height above the axle, plus shake
  Vec3 a = base.p - Vec3(0.0, 0.0, p_BI_.z()), a1 = base.d1, a2 = base.d2;
  double wave[4];
  for (int i = 0; i < 3; ++i) {
    sumOfSinusoids(options_.shake.position[i], w.s, wave);
    a[i] += wave[0], a1[i] += wave[1], a2[i] += wave[2];
  }
  CarFrame f;
  f.p = a;
  f.v = a1 * w.d1, f.a = a2 * w.d1 * w.d1 + a1 * w.d2;

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
  f.R = R_WB.R, f.dR = R_WB.dR, f.ddR = R_WB.ddR;
  return f;
}

CarFrame CarTrajectory::gradedFrame(double t) const {
  const PathTimeWarp w = rampedPathTime(t, options_.start_still_s, options_.ramp_s);
  const PathSample base = path_->at(w.s);
  const Terrain& ground = *options_.ground;
  const double L = options_.wheelbase, half_track = 0.5 * options_.track_width;

  // the ground under the four wheels, on the horizontal axes of the heading
  double heading[3];
  headingOf(base, heading);
  const Jet rear_left = groundUnder(ground, base, heading, 0.0, half_track);
  const Jet rear_right = groundUnder(ground, base, heading, 0.0, -half_track);
  const Jet front_left = groundUnder(ground, base, heading, L, half_track);
  const Jet front_right = groundUnder(ground, base, heading, L, -half_track);
  const Jet rear = 0.5 * (rear_left + rear_right), front = 0.5 * (front_left + front_right);
  // nose-up pitch from the axles' heights; roll from the left-right difference, tan(roll) =
  // cross slope x cos(pitch), which puts all four wheels on a plane exactly (README, "Terrain")
  const Jet pitch = inTime(atanOf((1.0 / L) * (front - rear)), w);
  const Jet cross = (0.5 / options_.track_width) * ((rear_left - rear_right) + (front_left - front_right));
  const Jet roll = inTime(atanOf(cross * cosOf(atanOf((1.0 / L) * (front - rear)))), w);

  // R_g = Rz(heading + yaw shake) Ry(-pitch) Rx(roll), then the shake's Ry(pitch) Rx(roll)
  double shake_roll[4], shake_pitch[4], yaw[4];
  sumOfSinusoids(options_.shake.attitude[0], w.s, shake_roll);
  sumOfSinusoids(options_.shake.attitude[1], w.s, shake_pitch);
  sumOfSinusoids(options_.shake.attitude[2], w.s, yaw);
  for (int k = 0; k < 3; ++k) yaw[k] += heading[k];
  double ang, dang, ddang;
  inTime(yaw, w, &ang, &dang, &ddang);
  RotationJet R_g = axisRotation(Vec3::UnitZ(), ang, dang, ddang);
  R_g = compose(R_g, axisRotation(Vec3::UnitY(), -pitch.f, -pitch.d1, -pitch.d2));
  R_g = compose(R_g, axisRotation(Vec3::UnitX(), roll.f, roll.d1, roll.d2));
  inTime(shake_pitch, w, &ang, &dang, &ddang);
  RotationJet R_WB = compose(R_g, axisRotation(Vec3::UnitY(), ang, dang, ddang));
  inTime(shake_roll, w, &ang, &dang, &ddang);
  R_WB = compose(R_WB, axisRotation(Vec3::UnitX(), ang, dang, ddang));

  // the rear wheels' contact centre G on the ground (plus the position shake), the axle the
  // clearance r above it along the car's z: A = G + R_g e_z r
  Vec3 g(base.p.x(), base.p.y(), rear.f), g1(base.d1.x(), base.d1.y(), rear.d1);
  Vec3 g2(base.d2.x(), base.d2.y(), rear.d2);
  double wave[4];
  for (int i = 0; i < 3; ++i) {
    sumOfSinusoids(options_.shake.position[i], w.s, wave);
    g[i] += wave[0], g1[i] += wave[1], g2[i] += wave[2];
  }
  const Jet r = inTime(Jet{base.p.z() - p_BI_.z(), base.d1.z(), base.d2.z()}, w);
  CarFrame f;
  f.p = g + R_g.R.col(2) * r.f;
  f.v = g1 * w.d1 + R_g.dR.col(2) * r.f + R_g.R.col(2) * r.d1;
  f.a = g2 * w.d1 * w.d1 + g1 * w.d2 + R_g.ddR.col(2) * r.f + 2.0 * R_g.dR.col(2) * r.d1 + R_g.R.col(2) * r.d2;
  f.R = R_WB.R, f.dR = R_WB.dR, f.ddR = R_WB.ddR;
  return f;
}

BodyState CarTrajectory::at(double t) const {
  const CarFrame f = frame(t);
  // the body origin rides on the car: p_I = A + R_WB p_BI
  const Mat3 R_BI = options_.T_I_B.linear().transpose();
  const Mat3 A = f.R.transpose() * f.dR;
  const Vec3 omega_B = so3::vee(0.5 * (A - A.transpose()));
  BodyState st;
  st.T_W_I.linear() = f.R * R_BI;
  st.T_W_I.translation() = f.p + f.R * p_BI_;
  st.velocity = f.v + f.dR * p_BI_;
  st.acceleration = f.a + f.ddR * p_BI_;
  st.angular_velocity = R_BI.transpose() * omega_B;
  return st;
}

}  // namespace livo::sim
