// Synthetic data with exact ground truth for the LIO tests and benchmarks: an analytic trajectory
// (exact body rates and specific force), scenes of boxes and planes, a spinning multi-beam LiDAR
// with per-point times ray-cast against them, and the IMU samples of the trajectory.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "livo/lio/imu_propagator.hpp"
#include "livo/sensor_samples.hpp"

namespace livo::lio::synth {

/// p(t) = p0 + sum_k a_k (1 - cos(w_k s)), φ(t) = φ0 + sum_k b_k (1 - cos(u_k s)), R = Exp(φ),
/// with s = max(0, t - t_still): still until t_still, then smooth motion from rest.
struct Trajectory {
  double t_still = 0.0;
  Vec3 p0 = Vec3::Zero();
  Vec3 phi0 = Vec3::Zero();
  std::vector<std::pair<Vec3, double>> pos_terms;  // (a_k, w_k)
  std::vector<std::pair<Vec3, double>> rot_terms;  // (b_k, u_k)
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);

  Pose3 pose(double t) const;
  Vec3 velocity(double t) const;
  Vec3 acceleration(double t) const;
  Vec3 omegaBody(double t) const;  // exact: Jr(φ) φ'
  /// Exact (noise-free) IMU reading at t.
  ImuSample imu(double t, int64_t utime) const;
  FilterState state(double t) const;
};

/// A walk through a room (28 x 14 m) at about 1 m/s with turns; still for `t_still` seconds.
Trajectory roomTrajectory(double t_still);
/// Down the corridor's axis (x) at about 1 m/s.
Trajectory corridorTrajectory(double t_still);

struct Box {
  Vec3 lo, hi;
};
struct InfinitePlane {
  Vec3 n;    // unit
  double d;  // n.x + d = 0
};

struct Scene {
  std::vector<Box> shells;   // seen from inside (rooms)
  std::vector<Box> solids;   // seen from outside (pillars, furniture)
  std::vector<InfinitePlane> planes;
  /// Distance along the unit ray to the first hit, or +inf.
  double raycast(const Vec3& o, const Vec3& d) const;
};

/// 28 x 14 x 4 m room with pillars and boxes.
Scene roomScene();
/// Two parallel walls (y = +-1.5) and a floor (z = -1.2), infinite along x.
Scene corridorScene();

struct LidarModel {
  int rings = 16;
  double fov_down_deg = -15.0, fov_up_deg = 15.0;
  int columns = 1800;          // firings per revolution
  double sweep_duration = 0.1; // s
  double min_range = 0.5, max_range = 100.0;
  double range_noise_std = 0.0;
  static LidarModel vlp16() { return {}; }
  static LidarModel hdl64() { return {64, -24.9, 2.0, 2048, 0.1, 0.5, 120.0, 0.0}; }
};

/// One sweep starting at utime (trajectory time t = (utime - base_utime) 1e-6), points in L:
/// the sensor moves along the trajectory during the sweep. T_I_L: p_I = T_I_L p_L.
LidarScan simulateSweep(const Scene& scene, const Trajectory& traj, const LidarModel& model, int64_t utime,
                        int64_t base_utime, const Pose3& T_I_L, std::mt19937* rng);

struct ImuErrorModel {
  ImuNoise noise;             // densities; all zero: exact samples
  Vec3 gyro_bias = Vec3::Zero();
  Vec3 accel_bias = Vec3::Zero();
  static ImuErrorModel exact() {
    ImuErrorModel m;
    m.noise = ImuNoise{0, 0, 0, 0};
    return m;
  }
};

/// IMU samples at rate_hz over [t0, t1] (trajectory time), stamped base_utime + t 1e6, with
/// white noise (density / sqrt(dt)) and constant biases.
std::vector<ImuSample> simulateImu(const Trajectory& traj, double t0, double t1, double rate_hz,
                                   int64_t base_utime, const ImuErrorModel& err, std::mt19937* rng);

/// A state away from every special case (turned on all axes, moving, biased, gravity tilted), for
/// Jacobian tests.
inline FilterState someState() {
  FilterState x;
  x.rot = so3::Exp(Vec3(0.3, -0.5, 1.2));
  x.pos = Vec3(1.0, -2.0, 0.5);
  x.vel = Vec3(0.7, 0.2, -0.1);
  x.gyro_bias = Vec3(0.01, -0.02, 0.015);
  x.accel_bias = Vec3(0.05, -0.03, 0.08);
  x.gravity = Vec3(0.1, -0.2, -9.8);
  return x;
}

/// Positions of est aligned onto gt by the best rigid transform (Umeyama, no scale); RMSE.
double alignedRmse(const std::vector<Vec3>& est, const std::vector<Vec3>& gt);

}  // namespace livo::lio::synth

namespace livo::lio::synth {

/// A whole synthetic run: IMU samples over the duration and sweeps generated on demand.
struct SequenceSpec {
  Scene scene = roomScene();
  Trajectory traj = roomTrajectory(1.0);
  LidarModel lidar = LidarModel::vlp16();
  double duration = 10.0;  // s
  double imu_rate = 200.0;
  ImuErrorModel imu_error = ImuErrorModel::exact();
  Pose3 T_I_L = Pose3::Identity();
  double lidar_time_offset = 0.0;  // t_imu = t_lidar + offset
  int64_t base_utime = 1'000'000'000;
  unsigned seed = 1;
};

/// Realistic IMU errors: the rig's densities and constant biases.
ImuErrorModel realisticImu();

class SyntheticSequence {
 public:
  explicit SyntheticSequence(SequenceSpec spec);
  const SequenceSpec& spec() const { return spec_; }
  const std::vector<ImuSample>& imu() const { return imu_; }
  int numScans() const;
  /// Sweep k (LiDAR clock), starting at trajectory time k * sweep_duration.
  LidarScan scan(int k) const;
  /// End of sweep k in the IMU clock.
  int64_t scanEndUtime(int k) const;
  Pose3 truth(int64_t imu_utime) const { return spec_.traj.pose(static_cast<double>(imu_utime - spec_.base_utime) * 1e-6); }

 private:
  SequenceSpec spec_;
  std::vector<ImuSample> imu_;
};

}  // namespace livo::lio::synth
