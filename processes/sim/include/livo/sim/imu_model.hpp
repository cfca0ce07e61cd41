// IMU measurement model: exact specific force and angular rate, the sensor's deterministic errors
// (scale factors, axis misalignment, gyro g-sensitivity, temperature-driven bias), then white
// noise and bias random walks with the usual continuous-time parameters (discrete std =
// density / sqrt(dt); bias step std = random_walk * sqrt(dt)).
#pragma once

#include "livo/sensor_rig.hpp"
#include "livo/sim/random.hpp"
#include "livo/sim/sensor_data.hpp"
#include "livo/sim/trajectory.hpp"

namespace livo::sim {

/// Noise-free reading of an IMU at the body origin.
ImuReading idealImuReading(const BodyState& state, double gravity, int64_t utime);

/// Die temperature: a linear ramp from start_c to end_c over ramp_s, constant afterwards.
struct ImuTemperature {
  double start_c = 25.0;
  double end_c = 25.0;
  double ramp_s = 600.0;
  double at(double t) const;
};

/// Deterministic errors of a MEMS IMU (all zero: an ideal sensor). The sensing axes are
///   K = (I + diag(scale_ppm * 1e-6)) * M,  M = [[1, 0, 0], [m0, 1, 0], [m1, m2, 1]], m = misalignment_mrad * 1e-3
/// (lower triangular: sensing x is the body x, sensing y lies in the body x-y plane, leaning by m0
/// towards x; sensing z leans by m1 towards x and m2 towards y), and a reading taken t seconds
/// after the start is
///   w_m = K_g w + diag(gyro_g_sensitivity) f + gyro_bias_per_c * (T(t) - T(0))
///   f_m = K_a f + accel_bias_per_c * (T(t) - T(0))
/// before the white noise and the random-walk bias are added.
struct ImuErrors {
  Vec3 gyro_scale_ppm = Vec3::Zero();
  Vec3 accel_scale_ppm = Vec3::Zero();
  Vec3 gyro_misalignment_mrad = Vec3::Zero();  // [m0, m1, m2]
  Vec3 accel_misalignment_mrad = Vec3::Zero();
  Vec3 gyro_g_sensitivity = Vec3::Zero();  // rad/s per m/s^2, per axis
  Vec3 gyro_bias_per_c = Vec3::Zero();     // rad/s per deg C
  Vec3 accel_bias_per_c = Vec3::Zero();    // m/s^2 per deg C
  ImuTemperature temperature;
  bool any() const;
};

/// K = (I + diag(scale_ppm * 1e-6)) * M(misalignment_mrad), see ImuErrors (livo::imuSensingAxes).
Mat3 sensingAxes(const Vec3& scale_ppm, const Vec3& misalignment_mrad);

/// Applies `errors` to an ideal reading taken t seconds after the start of the run.
void applyImuErrors(const ImuErrors& errors, double t, ImuReading* reading);

/// Every coefficient of `sigma` replaced by a zero-mean normal draw of that std (the temperature
/// profile is the environment, kept as given); the same seed gives the same sensor.
ImuErrors drawImuErrors(const ImuErrors& sigma, uint64_t seed);

/// Adds noise to readings in time order (the bias walk makes it sequential).
class ImuNoise {
 public:
  ImuNoise(const ImuRig& rig, const Vec3& initial_gyro_bias, const Vec3& initial_accel_bias, Random rng);
  void apply(ImuReading* reading);
  const Vec3& gyroBias() const { return gyro_bias_; }
  const Vec3& accelBias() const { return accel_bias_; }

 private:
  ImuRig rig_;
  double dt_;
  Vec3 gyro_bias_, accel_bias_;
  Random rng_;
};

}  // namespace livo::sim
