// Our undistortion against a real one: three Newer College sweeps (Ouster OS1-64, handheld,
// ../shared/data/lidar/newer_06): raw, deskewed by the dataset's own pipeline, and per-point times.
// Point i of raw is point i of theirs; their frame is the LiDAR's turned by pi about z plus a
// fixed translation (Ouster's lidar vs sensor frame), their reference time the sweep start; ours
// is the sweep end (LioEstimator::scanEndUtime). There is no IMU there, so the motion within a
// sweep is fitted (Gauss-Newton on the point-wise distance) as an IMU stream that the LIO's
// ImuPropagator integrates and its Undistorter applies: one constant rate and velocity (the
// model between two IMU samples), or the rates of a 200 Hz IMU.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "livo/lio/imu_propagator.hpp"
#include "livo/lio/lio_estimator.hpp"
#include "livo/lio/undistorter.hpp"

using namespace livo;
using namespace livo::lio;

namespace {

const std::string kNewer = std::string(LIVO_SHARED_DATA) + "/lidar/newer_06/";

std::vector<float> readFloats(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return {};
  std::vector<float> v(static_cast<size_t>(in.tellg()) / sizeof(float));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(float)));
  return v;
}

std::vector<Vec3> toPoints(const std::vector<float>& xyz) {
  std::vector<Vec3> p(xyz.size() / 3);
  for (size_t i = 0; i < p.size(); ++i) p[i] = Vec3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  return p;
}

struct RealSweep {
  LidarScan raw;               // LiDAR frame, times from the sweep start
  std::vector<Vec3> deskewed;  // theirs, point i of raw is point i here
};

/// Sweep k (raw_0k, deskewed_0k, times_0k: float32 x y z per point, float32 seconds per point).
bool loadSweep(int k, RealSweep* s) {
  const std::string id = "_0" + std::to_string(k) + ".bin";
  s->raw = LidarScan{};
  s->raw.utime = 1'000'000;
  s->raw.points = toPoints(readFloats(kNewer + "raw" + id));
  s->raw.time_offset = readFloats(kNewer + "times" + id);
  s->deskewed = toPoints(readFloats(kNewer + "deskewed" + id));
  return !s->raw.points.empty() && s->raw.points.size() == s->raw.time_offset.size() &&
         s->raw.points.size() == s->deskewed.size();
}

// Their sensor frame is the LiDAR frame turned by pi about z.
const Mat3 kR_I_L = so3::Exp(Vec3(0.0, 0.0, M_PI));

/// The motion over one sweep as the LIO sees it: an IMU stream from the sweep start to its end,
/// integrated by ImuPropagator with zero biases and gravity (so `accel` is the body's own
/// acceleration), the velocity at the start (frame of the body there) and the translation of the
/// extrinsic T_I_L = (kR_I_L, t_I_L).
struct SweepMotion {
  std::vector<ImuSample> imu;
  Vec3 velocity = Vec3::Zero();
  Vec3 t_I_L = Vec3::Zero();
};

/// The raw sweep through the LIO's propagation and Undistorter into the body frame at the sweep
/// start (`to_end` false: their convention) or at its end (the LIO's).
std::vector<Vec3> undistort(const LidarScan& scan, const SweepMotion& m, bool to_end) {
  FilterState x0;
  x0.vel = m.velocity;
  x0.gravity.setZero();
  ImuPropagator prop;
  prop.reset(x0, StateCovariance::Identity(), m.imu.front());
  for (size_t k = 1; k < m.imu.size(); ++k) prop.addSample(m.imu[k]);
  const FilterState& ref = to_end ? prop.state() : x0;
  const Undistorter und(prop.segments(), ref.rot, ref.pos, to_end ? prop.utime() : m.imu.front().utime,
                        se3::fromRotationTranslation(kR_I_L, m.t_I_L));
  std::vector<size_t> all(scan.points.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  std::vector<Vec3> out;
  und.undistort(scan, scan.utime, 0.0, all, &out);
  return out;
}

/// A family of motions over [start, end] (IMU clock) with `steps` equal propagation steps and the
/// extrinsic translation t_I_L: the parameters are the samples' gyro (constant: one for all) and
/// one acceleration for all samples (constant: none), then the start velocity.
struct MotionModel {
  int64_t start = 0, end = 0;
  int steps = 1;
  bool constant = true;
  Vec3 t_I_L = Vec3::Zero();

  int size() const { return (constant ? 3 : 3 * (steps + 1) + 3) + 3; }
  SweepMotion motion(const Eigen::VectorXd& x) const {
    SweepMotion m;
    const int n = size();
    for (int k = 0; k <= steps; ++k) {
      ImuSample s;
      s.utime = start + (end - start) * k / steps;
      s.gyro = constant ? x.segment<3>(0) : x.segment<3>(3 * k);
      if (!constant) s.accel = x.segment<3>(3 * (steps + 1));
      m.imu.push_back(s);
    }
    m.velocity = x.segment<3>(n - 3);
    m.t_I_L = t_I_L;
    return m;
  }
};

std::vector<double> distances(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  std::vector<double> d(a.size());
  for (size_t i = 0; i < a.size(); ++i) d[i] = (a[i] - b[i]).norm();
  return d;
}

double percentile(std::vector<double> v, double q) {
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

/// Least squares over all points (Gauss-Newton, Jacobian by central differences through the
/// propagation and the Undistorter, a little damping for the alternating sample pattern the
/// two-sample mean input cannot see): the motion that maps raw onto theirs.
SweepMotion fitMotion(const RealSweep& s, const MotionModel& model, bool to_end) {
  const int dim = model.size();
  const size_t n = s.deskewed.size();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(dim);
  for (int iter = 0; iter < 15; ++iter) {
    const std::vector<Vec3> base = undistort(s.raw, model.motion(x), to_end);
    Eigen::MatrixXd J(3 * n, dim);
    const double h = 1e-6;
    for (int k = 0; k < dim; ++k) {
      Eigen::VectorXd xp = x, xm = x;
      xp[k] += h;
      xm[k] -= h;
      const auto a = undistort(s.raw, model.motion(xp), to_end), b = undistort(s.raw, model.motion(xm), to_end);
      for (size_t i = 0; i < n; ++i) J.block<3, 1>(3 * i, k) = (a[i] - b[i]) / (2.0 * h);
    }
    Eigen::VectorXd r(3 * n);
    for (size_t i = 0; i < n; ++i) r.segment<3>(3 * i) = base[i] - s.deskewed[i];
    Eigen::MatrixXd H = J.transpose() * J;
    H.diagonal().array() += 1e-9 * H.trace() / dim;
    const Eigen::VectorXd dx = -H.ldlt().solve(J.transpose() * r);
    x += dx;
    if (dx.norm() < 1e-9) break;
  }
  return model.motion(x);
}

/// Every `stride`-th point of a sweep (the fit's sample; the figures are over all points).
RealSweep subsample(const RealSweep& s, size_t stride) {
  RealSweep out;
  out.raw.utime = s.raw.utime;
  out.raw.sweep_duration = s.raw.sweep_duration;
  for (size_t i = 0; i < s.deskewed.size(); i += stride) {
    out.raw.points.push_back(s.raw.points[i]);
    out.raw.time_offset.push_back(s.raw.time_offset[i]);
    out.deskewed.push_back(s.deskewed[i]);
  }
  return out;
}

struct Fit {
  SweepMotion motion;
  double median = 0.0, p95 = 0.0;  // point-wise distance to theirs over all points, m
};

Fit fitAndMeasure(const RealSweep& s, const MotionModel& model, bool to_end) {
  Fit f;
  f.motion = fitMotion(subsample(s, 4), model, to_end);
  const auto d = distances(undistort(s.raw, f.motion, to_end), s.deskewed);
  f.median = percentile(d, 0.5);
  f.p95 = percentile(d, 0.95);
  return f;
}

/// Raw against theirs with no motion (the same extrinsic): the distortion to remove.
Fit distortion(const RealSweep& s, const MotionModel& model) {
  Fit f;
  f.motion = model.motion(Eigen::VectorXd::Zero(model.size()));
  const auto d = distances(undistort(s.raw, f.motion, false), s.deskewed);
  f.median = percentile(d, 0.5);
  f.p95 = percentile(d, 0.95);
  return f;
}

/// The sweep's motion fitted to their convention and to ours, printed and checked: what our
/// undistortion leaves of the distortion, that the end is the wrong reference for their points,
/// and rates a handheld sensor can have.
/// Their first instant's points minus ours turned by pi about z, one per point at t = 0.
std::vector<Vec3> startOffsets(const RealSweep& s) {
  std::vector<Vec3> offsets;
  for (size_t i = 0; i < s.deskewed.size() && s.raw.time_offset[i] == 0.0f; ++i)
    offsets.push_back(s.deskewed[i] - kR_I_L * s.raw.points[i]);
  return offsets;
}

/// The LiDAR-to-sensor translation: the mean of the start offsets.
Vec3 startOffset(const RealSweep& s) {
  const std::vector<Vec3> o = startOffsets(s);
  Vec3 sum = Vec3::Zero();
  for (const Vec3& v : o) sum += v;
  return o.empty() ? sum : Vec3(sum / static_cast<double>(o.size()));
}

/// One sweep's motion fitted in a model, to their reference (the start) and, if asked, to the
/// LIO's (the end), printed.
struct SweepFit {
  Fit start, end, raw;  // raw: the distortion, raw against theirs with no motion
  double max_rate = 0.0;
};

SweepFit fitSweep(int k, int steps, bool also_to_end) {
  SweepFit f;
  RealSweep s;
  if (!loadSweep(k, &s)) throw std::runtime_error("cannot read Newer College sweep " + std::to_string(k));
  const MotionModel model{s.raw.utime, LioEstimator{}.scanEndUtime(s.raw), steps, steps == 1, startOffset(s)};
  f.start = fitAndMeasure(s, model, false);
  if (also_to_end) f.end = fitAndMeasure(s, model, true);
  f.raw = distortion(s, model);
  const SweepMotion& m = f.start.motion;
  // the rate of each step is the mean of its two samples (what the propagation integrates)
  Vec3 mean_rate = Vec3::Zero();
  for (size_t j = 1; j < m.imu.size(); ++j) {
    const Vec3 w = 0.5 * (m.imu[j - 1].gyro + m.imu[j].gyro);
    f.max_rate = std::max(f.max_rate, w.norm());
    mean_rate += w / static_cast<double>(m.imu.size() - 1);
  }
  std::printf(
      "[newer-deskew] sweep %d, %d step(s): raw vs theirs median %.1f mm p95 %.1f mm | ours to the start "
      "median %.2f mm p95 %.2f mm\n",
      k, steps, f.raw.median * 1e3, f.raw.p95 * 1e3, f.start.median * 1e3, f.start.p95 * 1e3);
  if (also_to_end)
    std::printf("[newer-deskew]   to the end median %.1f mm p95 %.1f mm\n", f.end.median * 1e3, f.end.p95 * 1e3);
  std::printf(
      "[newer-deskew]   mean rate %+.3f %+.3f %+.3f rad/s (step max %.3f), v %+.3f %+.3f %+.3f m/s, "
      "acc %+.2f %+.2f %+.2f m/s^2\n",
      mean_rate.x(), mean_rate.y(), mean_rate.z(), f.max_rate, m.velocity.x(), m.velocity.y(), m.velocity.z(),
      m.imu[0].accel.x(), m.imu[0].accel.y(), m.imu[0].accel.z());
  return f;
}

/// At least 90 % of the distortion removed, and a motion a handheld sensor can have: less than a
/// turn a second, a running pace, 3 g.
void expectRemovedPlausibly(const SweepFit& f, int k) {
  EXPECT_LT(f.start.median, 0.1 * f.raw.median) << "sweep " << k;
  EXPECT_LT(f.start.p95, 0.1 * f.raw.p95) << "sweep " << k;
  EXPECT_LT(f.max_rate, 2.0 * M_PI) << "sweep " << k;
  EXPECT_LT(f.start.motion.velocity.norm(), 3.0) << "sweep " << k;
  EXPECT_LT(f.start.motion.imu[0].accel.norm(), 30.0) << "sweep " << k;
}

bool haveData() {
  RealSweep probe;
  for (int k = 0; k < 3; ++k)
    if (!loadSweep(k, &probe)) return false;
  return true;
}

}  // namespace

// Point i of raw is point i of theirs, their frame is ours turned by pi about z, and their
// reference is the sweep start: the points of the first instant differ from raw by one constant
// offset (the LiDAR-to-sensor translation), to the float precision.
TEST(RealDeskew, NewerCollegeFrameAndIndices) {
  if (!haveData()) GTEST_SKIP() << "no Newer College sweeps in " << kNewer << " (../shared/data absent)";
  for (int k = 0; k < 3; ++k) {
    RealSweep s;
    ASSERT_TRUE(loadSweep(k, &s));
    const std::vector<Vec3> offsets = startOffsets(s);
    ASSERT_GE(offsets.size(), 8u) << "sweep " << k;
    double spread = 0.0;
    for (const Vec3& o : offsets) spread = std::max(spread, (o - offsets.front()).norm());
    std::printf("[newer-deskew] sweep %d: %zu points at t = 0, offset %+.4f %+.4f %+.4f m, spread %.2e m\n", k,
                offsets.size(), offsets[0].x(), offsets[0].y(), offsets[0].z(), spread);
    EXPECT_LT(spread, 1e-4) << "sweep " << k;
    EXPECT_LT(offsets.front().norm(), 0.05) << "sweep " << k;
  }
}

// The constant body twist (one propagation step, no acceleration), the motion the LIO assumes
// between two IMU samples: it removes most of the distortion, but only undistorting to the sweep
// start; to the end (the LIO's reference) the error is ten times larger. What is left to the start
// (5-50 mm median) is the motion's change within the sweep, see the next test.
TEST(RealDeskew, NewerCollegeConstantTwist) {
  if (!haveData()) GTEST_SKIP() << "no Newer College sweeps in " << kNewer << " (../shared/data absent)";
  for (int k = 0; k < 3; ++k) {
    const SweepFit f = fitSweep(k, 1, true);
    expectRemovedPlausibly(f, k);
    EXPECT_GT(f.end.median, 10.0 * f.start.median) << "sweep " << k;
    EXPECT_GT(f.end.p95, 10.0 * f.start.p95) << "sweep " << k;
  }
}

// The rates of a 200 Hz IMU (20 propagation steps, one acceleration over the sweep): our
// propagation and undistortion reproduce theirs to a few millimetres. (A motion this flexible
// bends most of a sweep onto theirs from the wrong reference too, so the reference is proven by
// the first instant's points and by the constant twist.)
TEST(RealDeskew, NewerCollegeImuRateMotion) {
  if (!haveData()) GTEST_SKIP() << "no Newer College sweeps in " << kNewer << " (../shared/data absent)";
  for (int k = 0; k < 3; ++k) {
    const SweepFit f = fitSweep(k, 20, false);
    expectRemovedPlausibly(f, k);
    EXPECT_LT(f.start.median, 4e-3) << "sweep " << k;
    EXPECT_LT(f.start.p95, 35e-3) << "sweep " << k;
  }
}
