#include "synthetic_world.hpp"

#include <Eigen/SVD>
#include <cmath>
#include <limits>

namespace livo::lio::synth {

namespace {
double sOf(const Trajectory& tr, double t) { return std::max(0.0, t - tr.t_still); }
Vec3 phiOf(const Trajectory& tr, double s) {
  Vec3 phi = tr.phi0;
  for (const auto& [b, u] : tr.rot_terms) phi += b * (1.0 - std::cos(u * s));
  return phi;
}
Vec3 phiDot(const Trajectory& tr, double s) {
  Vec3 d = Vec3::Zero();
  if (s <= 0.0) return d;
  for (const auto& [b, u] : tr.rot_terms) d += b * u * std::sin(u * s);
  return d;
}
}  // namespace

Pose3 Trajectory::pose(double t) const {
  const double s = sOf(*this, t);
  Vec3 p = p0;
  for (const auto& [a, w] : pos_terms) p += a * (1.0 - std::cos(w * s));
  return se3::fromRotationTranslation(so3::Exp(phiOf(*this, s)), p);
}

Vec3 Trajectory::velocity(double t) const {
  const double s = sOf(*this, t);
  Vec3 v = Vec3::Zero();
  if (s <= 0.0) return v;
  for (const auto& [a, w] : pos_terms) v += a * w * std::sin(w * s);
  return v;
}

Vec3 Trajectory::acceleration(double t) const {
  const double s = sOf(*this, t);
  Vec3 acc = Vec3::Zero();
  if (s <= 0.0) return acc;
  for (const auto& [a, w] : pos_terms) acc += a * w * w * std::cos(w * s);
  return acc;
}

Vec3 Trajectory::omegaBody(double t) const {
  const double s = sOf(*this, t);
  return so3::rightJacobian(phiOf(*this, s)) * phiDot(*this, s);
}

ImuSample Trajectory::imu(double t, int64_t utime) const {
  ImuSample m;
  m.utime = utime;
  m.gyro = omegaBody(t);
  m.accel = pose(t).linear().transpose() * (acceleration(t) - gravity);
  return m;
}

FilterState Trajectory::state(double t) const {
  FilterState x;
  const Pose3 T = pose(t);
  x.rot = T.linear();
  x.pos = T.translation();
  x.vel = velocity(t);
  x.gravity = gravity;
  return x;
}

Trajectory roomTrajectory(double t_still) {
  Trajectory tr;
  tr.t_still = t_still;
  tr.p0 = Vec3(-4.0, -1.0, 1.2);
  tr.phi0 = Vec3(0.02, -0.03, 0.3);
  tr.pos_terms = {{Vec3(-3.0, 1.5, 0.1), 0.35}, {Vec3(0.6, -1.2, 0.05), 0.8}};
  tr.rot_terms = {{Vec3(0.0, 0.0, 0.9), 0.5}, {Vec3(0.05, -0.04, 0.2), 1.3}};
  return tr;
}

Trajectory corridorTrajectory(double t_still) {
  Trajectory tr;
  tr.t_still = t_still;
  tr.p0 = Vec3(0.0, 0.0, 0.0);
  tr.phi0 = Vec3(0.0, 0.0, 0.1);
  tr.pos_terms = {{Vec3(-6.0, 0.3, 0.05), 0.25}, {Vec3(0.2, 0.2, 0.02), 0.9}};
  tr.rot_terms = {{Vec3(0.03, 0.02, -0.2), 0.7}};
  return tr;
}

double Scene::raycast(const Vec3& o, const Vec3& d) const {
  double best = std::numeric_limits<double>::infinity();
  auto slab = [&](const Box& b, double* tnear, double* tfar) {
    double t0 = -std::numeric_limits<double>::infinity(), t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      if (std::abs(d[a]) < 1e-12) {
        if (o[a] < b.lo[a] || o[a] > b.hi[a]) return false;
        continue;
      }
      double ta = (b.lo[a] - o[a]) / d[a], tb = (b.hi[a] - o[a]) / d[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    *tnear = t0;
    *tfar = t1;
    return t0 <= t1;
  };
  for (const auto& b : shells) {
    double t0, t1;
    if (slab(b, &t0, &t1) && t1 > 0.0) best = std::min(best, t1);
  }
  for (const auto& b : solids) {
    double t0, t1;
    if (slab(b, &t0, &t1) && t0 > 0.0) best = std::min(best, t0);
  }
  for (const auto& p : planes) {
    const double den = p.n.dot(d);
    if (std::abs(den) < 1e-12) continue;
    const double t = -(p.n.dot(o) + p.d) / den;
    if (t > 0.0) best = std::min(best, t);
  }
  return best;
}

Scene roomScene() {
  Scene s;
  s.shells.push_back({Vec3(-14.0, -7.0, 0.0), Vec3(14.0, 7.0, 4.0)});
  s.solids.push_back({Vec3(-8.5, 2.0, 0.0), Vec3(-7.5, 3.0, 4.0)});
  s.solids.push_back({Vec3(1.0, -5.0, 0.0), Vec3(2.0, -4.0, 4.0)});
  s.solids.push_back({Vec3(5.0, 3.0, 0.0), Vec3(7.0, 4.5, 1.0)});
  s.solids.push_back({Vec3(-2.0, 4.0, 0.0), Vec3(-1.2, 6.0, 2.0)});
  s.solids.push_back({Vec3(9.0, -6.0, 0.0), Vec3(11.0, -3.0, 1.5)});
  return s;
}

Scene corridorScene() {
  Scene s;
  s.planes.push_back({Vec3(0.0, 1.0, 0.0), 1.5});    // y = -1.5
  s.planes.push_back({Vec3(0.0, -1.0, 0.0), 1.5});   // y = 1.5
  s.planes.push_back({Vec3(0.0, 0.0, 1.0), 1.2});    // z = -1.2
  return s;
}

LidarScan simulateSweep(const Scene& scene, const Trajectory& traj, const LidarModel& m, int64_t utime,
                        int64_t base_utime, const Pose3& T_I_L, std::mt19937* rng) {
  LidarScan scan;
  scan.utime = utime;
  scan.sweep_duration = m.sweep_duration;
  const size_t n = static_cast<size_t>(m.rings) * static_cast<size_t>(m.columns);
  scan.points.reserve(n);
  scan.time_offset.reserve(n);
  scan.intensity.reserve(n);
  scan.ring.reserve(n);
  std::normal_distribution<double> noise(0.0, 1.0);
  const double t0 = static_cast<double>(utime - base_utime) * 1e-6;
  std::vector<Vec3> dirs(static_cast<size_t>(m.rings));
  for (int c = 0; c < m.columns; ++c) {
    const double dt = m.sweep_duration * c / m.columns;
    const Pose3 T_W_L = traj.pose(t0 + dt) * T_I_L;
    const double az = 2.0 * M_PI * c / m.columns;
    for (int r = 0; r < m.rings; ++r) {
      const double el = (m.fov_down_deg + (m.fov_up_deg - m.fov_down_deg) * r / std::max(1, m.rings - 1)) * M_PI / 180.0;
      const Vec3 d_L(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      const Vec3 d_W = T_W_L.linear() * d_L;
      double range = scene.raycast(T_W_L.translation(), d_W);
      if (!std::isfinite(range) || range > m.max_range || range < m.min_range) continue;
      if (m.range_noise_std > 0.0) range += m.range_noise_std * noise(*rng);
      scan.points.push_back(d_L * range);
      scan.time_offset.push_back(static_cast<float>(dt));
      scan.intensity.push_back(static_cast<float>(r));
      scan.ring.push_back(static_cast<int16_t>(r));
    }
  }
  return scan;
}

std::vector<ImuSample> simulateImu(const Trajectory& traj, double t0, double t1, double rate_hz, int64_t base_utime,
                                   const ImuErrorModel& err, std::mt19937* rng) {
  std::vector<ImuSample> out;
  const double dt = 1.0 / rate_hz;
  std::normal_distribution<double> n01(0.0, 1.0);
  const double sg = err.noise.gyro_noise_density / std::sqrt(dt), sa = err.noise.accel_noise_density / std::sqrt(dt);
  const int64_t i0 = static_cast<int64_t>(std::ceil(t0 * rate_hz - 1e-9));
  const int64_t i1 = static_cast<int64_t>(std::floor(t1 * rate_hz + 1e-9));
  for (int64_t i = i0; i <= i1; ++i) {
    const double t = static_cast<double>(i) / rate_hz;
    ImuSample s = traj.imu(t, base_utime + static_cast<int64_t>(std::llround(t * 1e6)));
    s.gyro += err.gyro_bias;
    s.accel += err.accel_bias;
    if (sg > 0.0 || sa > 0.0) {
      for (int a = 0; a < 3; ++a) s.gyro[a] += sg * n01(*rng);
      for (int a = 0; a < 3; ++a) s.accel[a] += sa * n01(*rng);
    }
    out.push_back(s);
  }
  return out;
}

double alignedRmse(const std::vector<Vec3>& est, const std::vector<Vec3>& gt) {
  const size_t n = std::min(est.size(), gt.size());
  if (n == 0) return 0.0;
  Vec3 me = Vec3::Zero(), mg = Vec3::Zero();
  for (size_t i = 0; i < n; ++i) {
    me += est[i];
    mg += gt[i];
  }
  me /= static_cast<double>(n);
  mg /= static_cast<double>(n);
  Mat3 C = Mat3::Zero();
  for (size_t i = 0; i < n; ++i) C += (gt[i] - mg) * (est[i] - me).transpose();
  Eigen::JacobiSVD<Mat3> svd(C, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 Sg = Mat3::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) Sg(2, 2) = -1.0;
  const Mat3 R = svd.matrixU() * Sg * svd.matrixV().transpose();
  const Vec3 t = mg - R * me;
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) sum += (R * est[i] + t - gt[i]).squaredNorm();
  return std::sqrt(sum / static_cast<double>(n));
}

}  // namespace livo::lio::synth

namespace livo::lio::synth {

ImuErrorModel realisticImu() {
  ImuErrorModel m;
  m.noise = ImuNoise{1.7e-4, 2.0e-3, 1.9e-5, 3.0e-3};
  m.gyro_bias = Vec3(0.002, -0.0015, 0.001);
  m.accel_bias = Vec3(0.03, -0.02, 0.04);
  return m;
}

SyntheticSequence::SyntheticSequence(SequenceSpec spec) : spec_(std::move(spec)) {
  std::mt19937 rng(spec_.seed);
  imu_ = simulateImu(spec_.traj, 0.0, spec_.duration + 0.2, spec_.imu_rate, spec_.base_utime, spec_.imu_error, &rng);
}

int SyntheticSequence::numScans() const {
  return static_cast<int>(std::floor(spec_.duration / spec_.lidar.sweep_duration + 1e-9));
}

LidarScan SyntheticSequence::scan(int k) const {
  std::mt19937 rng(spec_.seed * 7919u + static_cast<unsigned>(k));
  const int64_t start_imu = spec_.base_utime + static_cast<int64_t>(std::llround(k * spec_.lidar.sweep_duration * 1e6));
  LidarScan s = simulateSweep(spec_.scene, spec_.traj, spec_.lidar, start_imu, spec_.base_utime, spec_.T_I_L, &rng);
  s.utime = start_imu - static_cast<int64_t>(std::llround(spec_.lidar_time_offset * 1e6));
  return s;
}

int64_t SyntheticSequence::scanEndUtime(int k) const {
  return spec_.base_utime + static_cast<int64_t>(std::llround((k + 1) * spec_.lidar.sweep_duration * 1e6));
}

}  // namespace livo::lio::synth
