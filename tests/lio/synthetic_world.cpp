#include "synthetic_world.hpp"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
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
  for (const auto& g : grounds) best = std::min(best, g.raycast(o, d));
  return best;
}

double GradedGround::height(double at_x) const {
  if (x.empty()) return 0.0;
  if (at_x <= x.front()) return h.front();
  if (at_x >= x.back()) return h.back();
  const size_t i =
      static_cast<size_t>(std::upper_bound(x.begin(), x.end(), at_x) - x.begin());  // x[i-1] <= at_x < x[i]
  return h[i - 1] + (h[i] - h[i - 1]) * (at_x - x[i - 1]) / (x[i] - x[i - 1]);
}

double GradedGround::grade(double at_x) const {
  if (x.size() < 2 || at_x < x.front() || at_x >= x.back()) return 0.0;
  const size_t i = static_cast<size_t>(std::upper_bound(x.begin(), x.end(), at_x) - x.begin());
  return (h[i] - h[i - 1]) / (x[i] - x[i - 1]);
}

double GradedGround::raycast(const Vec3& o, const Vec3& d) const {
  double best = std::numeric_limits<double>::infinity();
  if (x.empty()) return best;
  const double inf = std::numeric_limits<double>::infinity();
  // piece j spans [x[j-1], x[j]] (x[-1] = -inf, x[n] = +inf): z = h(x_ref) + g (x - x_ref)
  for (size_t j = 0; j <= x.size(); ++j) {
    const double lo = j == 0 ? -inf : x[j - 1], hi = j == x.size() ? inf : x[j];
    const double x_ref = j == 0 ? x.front() : x[j - 1];
    const double h_ref = j == 0 ? h.front() : h[j - 1];
    const double g = (j == 0 || j == x.size()) ? 0.0 : (h[j] - h[j - 1]) / (x[j] - x[j - 1]);
    const double den = d.z() - g * d.x();
    if (std::abs(den) < 1e-12) continue;
    const double t = (h_ref + g * (o.x() - x_ref) - o.z()) / den;
    if (!(t > 0.0) || t >= best) continue;
    const double xh = o.x() + t * d.x();
    if (xh >= lo - 1e-9 && xh <= hi + 1e-9) best = t;
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
  s.planes.push_back({Vec3(0.0, 1.0, 0.0), 1.5});   // y = -1.5
  s.planes.push_back({Vec3(0.0, -1.0, 0.0), 1.5});  // y = 1.5
  s.planes.push_back({Vec3(0.0, 0.0, 1.0), 1.2});   // z = -1.2
  return s;
}

GradedGround gradedRoad() {
  GradedGround g;
  g.x = {20.0, 50.0, 75.0};
  g.h = {0.0, 1.5, 0.5};
  return g;
}

Scene gradedRoadScene(const GradedGround& ground) {
  Scene s;
  s.grounds.push_back(ground);
  auto standing = [&](double x, double y, double half_x, double half_y, double tall) {
    const double foot = ground.height(x);  // the piece under its centre; 1 m buried covers a 5 % grade
    s.solids.push_back({Vec3(x - half_x, y - half_y, foot - 1.0), Vec3(x + half_x, y + half_y, foot + tall)});
  };
  // poles about every 30 m, alternating sides, not evenly (a regular pattern aliases along the road)
  const double pole_x[] = {-25.0, 4.0, 31.0, 63.0, 89.0, 118.0, 146.0};
  for (int i = 0; i < 7; ++i) standing(pole_x[i], (i % 2 == 0 ? 1.0 : -1.0) * (6.0 + 0.4 * i), 0.15, 0.15, 5.0);
  // low buildings, well off the road
  standing(-12.0, -15.0, 4.0, 2.5, 3.0);
  standing(40.0, 14.0, 5.0, 3.0, 3.5);
  standing(102.0, -16.0, 6.0, 3.0, 3.0);
  return s;
}

namespace {
/// The ground's profile with each knot rounded into a parabolic vertical curve `curve` m long
/// (centred on the knot): its height and slope.
void roundedProfile(const GradedGround& g, double x, double curve, double* height, double* slope) {
  *height = g.height(x);
  *slope = g.grade(x);
  for (size_t i = 0; i < g.x.size(); ++i) {
    const double u = x - g.x[i] + 0.5 * curve;
    if (u <= 0.0 || u >= curve) continue;
    const double before = g.grade(g.x[i] - 1e-9), after = g.grade(g.x[i]);
    const double change = after - before;
    *height = g.h[i] + before * (x - g.x[i]) + change * u * u / (2.0 * curve);
    *slope = before + change * u / curve;
  }
}

/// Coefficients c_k of f(s) - f(0) ~ sum_k c_k (1 - cos(k pi s / span)), k = 1..K, least squares
/// over samples of [0, span].
std::vector<double> fitCosines(const std::vector<double>& s, const std::vector<double>& f, double span, int K) {
  Eigen::MatrixXd M(static_cast<Eigen::Index>(s.size()), K);
  Eigen::VectorXd b(static_cast<Eigen::Index>(s.size()));
  for (size_t j = 0; j < s.size(); ++j) {
    for (int k = 0; k < K; ++k) M(static_cast<Eigen::Index>(j), k) = 1.0 - std::cos((k + 1) * M_PI * s[j] / span);
    b(static_cast<Eigen::Index>(j)) = f[j] - f.front();
  }
  const Eigen::VectorXd c = M.colPivHouseholderQr().solve(b);
  return std::vector<double>(c.data(), c.data() + K);
}
}  // namespace

Trajectory gradedDrive(const GradedGround& ground, double t_still, double duration, double distance, double height,
                       double curve_length) {
  Trajectory tr;
  tr.t_still = t_still;
  const double drive = duration - t_still;
  // along x: from rest, two thirds of the way to the half period's turning point at `duration`
  const double w = M_PI / (1.5 * drive);
  const double A = distance / (1.0 - std::cos(w * drive));
  tr.pos_terms = {{Vec3(A, 0.0, 0.0), w}};
  // height and pitch fitted over a span a little past the end (the IMU runs on), ending level
  const double span = drive + 2.0;
  const int K = 60;
  std::vector<double> s, z, pitch;
  for (int j = 0; j <= 4000; ++j) {
    s.push_back(span * j / 4000.0);
    const double x = A * (1.0 - std::cos(w * s.back()));
    double hz, slope;
    roundedProfile(ground, x, curve_length, &hz, &slope);
    z.push_back(hz + height);
    pitch.push_back(-std::atan(slope));  // nose up climbing: a negative turn about y
  }
  tr.p0 = Vec3(0.0, 0.0, z.front());
  tr.phi0 = Vec3(0.0, pitch.front(), 0.0);
  const std::vector<double> cz = fitCosines(s, z, span, K), cp = fitCosines(s, pitch, span, K);
  for (int k = 0; k < K; ++k) {
    tr.pos_terms.push_back({Vec3(0.0, 0.0, cz[static_cast<size_t>(k)]), (k + 1) * M_PI / span});
    tr.rot_terms.push_back({Vec3(0.0, cp[static_cast<size_t>(k)], 0.0), (k + 1) * M_PI / span});
  }
  return tr;
}

double gradedDriveHeightError(const Trajectory& traj, const GradedGround& ground, double duration, double height) {
  double worst = 0.0;
  for (double t = 0.0; t <= duration; t += 0.01) {
    const Vec3 p = traj.pose(t).translation();
    worst = std::max(worst, std::abs(p.z() - ground.height(p.x()) - height));
  }
  return worst;
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
      const double el =
          (m.fov_down_deg + (m.fov_up_deg - m.fov_down_deg) * r / std::max(1, m.rings - 1)) * M_PI / 180.0;
      const Vec3 d_L(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      Vec3 d_W = T_W_L.linear() * d_L;
      if (m.elevation_error_deg != 0.0) {
        const double el_true = el + m.elevation_error_deg * M_PI / 180.0;
        d_W = T_W_L.linear() *
              Vec3(std::cos(el_true) * std::cos(az), std::cos(el_true) * std::sin(az), std::sin(el_true));
      }
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
