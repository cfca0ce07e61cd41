#include "livo/sim/imu_model.hpp"

#include <algorithm>
#include <cmath>

#include "livo/imu_axes.hpp"
#include "livo/sim/calibration_errors.hpp"

namespace livo::sim {

ImuReading idealImuReading(const BodyState& state, double gravity, int64_t utime) {
  ImuReading r;
  r.utime = utime;
  r.angular_velocity = state.angular_velocity;
  r.linear_acceleration = specificForce(state, gravity);
  return r;
}

double ImuTemperature::at(double t) const {
  const double x = ramp_s > 0.0 ? std::clamp(t / ramp_s, 0.0, 1.0) : 1.0;
  return start_c + (end_c - start_c) * x;
}

bool ImuErrors::any() const {
  for (const Vec3* v : {&gyro_scale_ppm, &accel_scale_ppm, &gyro_misalignment_mrad, &accel_misalignment_mrad,
                        &gyro_g_sensitivity, &gyro_bias_per_c, &accel_bias_per_c})
    if (!v->isZero(0.0)) return true;
  return false;
}

Mat3 sensingAxes(const Vec3& scale_ppm, const Vec3& misalignment_mrad) {
  return imuSensingAxes(scale_ppm * 1e-6, misalignment_mrad * 1e-3);
}

void applyImuErrors(const ImuErrors& e, double t, ImuReading* r) {
  const Vec3 w = r->angular_velocity, f = r->linear_acceleration;
  const double dT = e.temperature.at(t) - e.temperature.at(0.0);
  r->angular_velocity = sensingAxes(e.gyro_scale_ppm, e.gyro_misalignment_mrad) * w +
                        e.gyro_g_sensitivity.cwiseProduct(f) + e.gyro_bias_per_c * dT;
  r->linear_acceleration = sensingAxes(e.accel_scale_ppm, e.accel_misalignment_mrad) * f + e.accel_bias_per_c * dT;
}

ImuErrors drawImuErrors(const ImuErrors& sigma, uint64_t seed) {
  ImuErrors e;
  e.gyro_scale_ppm = drawError(sigma.gyro_scale_ppm, seed, "imu.gyro_scale_ppm");
  e.accel_scale_ppm = drawError(sigma.accel_scale_ppm, seed, "imu.accel_scale_ppm");
  e.gyro_misalignment_mrad = drawError(sigma.gyro_misalignment_mrad, seed, "imu.gyro_misalignment_mrad");
  e.accel_misalignment_mrad = drawError(sigma.accel_misalignment_mrad, seed, "imu.accel_misalignment_mrad");
  e.gyro_g_sensitivity = drawError(sigma.gyro_g_sensitivity, seed, "imu.gyro_g_sensitivity");
  e.gyro_bias_per_c = drawError(sigma.gyro_bias_per_c, seed, "imu.gyro_bias_per_c");
  e.accel_bias_per_c = drawError(sigma.accel_bias_per_c, seed, "imu.accel_bias_per_c");
  e.temperature = sigma.temperature;
  return e;
}

ImuNoise::ImuNoise(const ImuRig& rig, const Vec3& initial_gyro_bias, const Vec3& initial_accel_bias, Random rng)
    : rig_(rig), dt_(1.0 / rig.rate_hz), gyro_bias_(initial_gyro_bias), accel_bias_(initial_accel_bias), rng_(rng) {}

void ImuNoise::apply(ImuReading* r) {
  const double sq = std::sqrt(dt_);
  r->angular_velocity += gyro_bias_ + rng_.normal3() * (rig_.gyro_noise_density / sq);
  r->linear_acceleration += accel_bias_ + rng_.normal3() * (rig_.accel_noise_density / sq);
  gyro_bias_ += rng_.normal3() * (rig_.gyro_random_walk * sq);
  accel_bias_ += rng_.normal3() * (rig_.accel_random_walk * sq);
}

}  // namespace livo::sim
