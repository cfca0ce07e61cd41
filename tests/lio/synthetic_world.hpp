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

/// A ground of planar pieces along x, the same at every y (a road's grade profile without camber):
/// its height is linear between the knots (x[i], h[i]) (x ascending) and level beyond the first
/// and the last. A height field: a ray from above it meets it first where the nearest of the
/// pieces' planes, hit within the piece's own x interval, is met.
struct GradedGround {
  std::vector<double> x, h;
  double height(double at_x) const;
  /// The slope dh/dx of the piece at x (the right one at a knot).
  double grade(double at_x) const;
  /// Distance along the unit ray from o to the ground, or +inf (exact: a plane per piece).
  double raycast(const Vec3& o, const Vec3& d) const;
};

struct Scene {
  std::vector<Box> shells;  // seen from inside (rooms)
  std::vector<Box> solids;  // seen from outside (pillars, furniture)
  std::vector<InfinitePlane> planes;
  std::vector<GradedGround> grounds;
  /// Distance along the unit ray to the first hit, or +inf.
  double raycast(const Vec3& o, const Vec3& d) const;
};

/// 28 x 14 x 4 m room with pillars and boxes.
Scene roomScene();
/// Two parallel walls (y = +-1.5) and a floor (z = -1.2), infinite along x.
Scene corridorScene();

/// A road along +x with grade changes (planar pieces, sharp knots): level until x = 20 m, 5 % up to
/// x = 50 m (+1.5 m), a crest, 4 % down to x = 75 m (+0.5 m), then level again.
GradedGround gradedRoad();
/// The road and, far apart as outdoors, poles (0.3 m square, 5 m tall) about every 30 m on either
/// side 6-8.4 m from the centre line and three low buildings 11-13 m out; everything stands on the
/// ground (its foot 1 m below it). The LiDAR's height comes from the ground alone: the structure
/// is vertical, its tops above the sensor.
Scene gradedRoadScene(const GradedGround& ground = gradedRoad());
/// A vehicle driving along +x over `ground` (heading along x), still for `t_still` s, then from rest
/// x(s) = A (1 - cos(w s)), reaching `distance` m at `duration` at about 5 m/s (w: two thirds of the
/// way to the half period's turning point); its height `height` m above the ground and its pitch
/// the ground's grade (nose up climbing), each a sum of 60 cosines fitted (least squares over
/// samples, deterministic) to the profile with every knot rounded into a parabolic vertical curve
/// `curve_length` m long, so that pose, velocity, rates and specific force stay analytic and the
/// IMU exact. Over a sharp knot the body floats up to grade change x curve_length / 8 off `height`
/// (6.5 cm at gradedRoad()'s crest with 6 m curves): a suspension. gradedDriveHeightError() gives it.
Trajectory gradedDrive(const GradedGround& ground, double t_still, double duration, double distance = 100.0,
                       double height = 1.8, double curve_length = 6.0);
/// The largest |z - ground(x) - height| of the drive over [0, duration] (m).
double gradedDriveHeightError(const Trajectory& traj, const GradedGround& ground, double duration, double height);

struct LidarModel {
  int rings = 16;
  double fov_down_deg = -15.0, fov_up_deg = 15.0;
  int columns = 1800;           // firings per revolution
  double sweep_duration = 0.1;  // s
  double min_range = 0.5, max_range = 100.0;
  double range_noise_std = 0.0;
  // An intrinsic calibration error: every beam leaves this much above its nominal elevation, the
  // points reported along the nominal (0: none). Far ground then lies lower than near ground.
  double elevation_error_deg = 0.0;
  static LidarModel vlp16() { return {}; }
  static LidarModel hdl64() { return {64, -24.9, 2.0, 2048, 0.1, 0.5, 120.0, 0.0}; }
};

/// One sweep starting at utime (trajectory time t = (utime - base_utime) 1e-6), points in L:
/// the sensor moves along the trajectory during the sweep. T_I_L: p_I = T_I_L p_L.
LidarScan simulateSweep(const Scene& scene, const Trajectory& traj, const LidarModel& model, int64_t utime,
                        int64_t base_utime, const Pose3& T_I_L, std::mt19937* rng);

struct ImuErrorModel {
  ImuNoise noise;  // densities; all zero: exact samples
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
std::vector<ImuSample> simulateImu(const Trajectory& traj, double t0, double t1, double rate_hz, int64_t base_utime,
                                   const ImuErrorModel& err, std::mt19937* rng);

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
  Pose3 truth(int64_t imu_utime) const {
    return spec_.traj.pose(static_cast<double>(imu_utime - spec_.base_utime) * 1e-6);
  }

 private:
  SequenceSpec spec_;
  std::vector<ImuSample> imu_;
};

}  // namespace livo::lio::synth
