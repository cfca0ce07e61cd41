#include "imu_model.hpp"

#include <cmath>

namespace livo {
namespace sim {

ImuReading idealImuReading(const BodyState& state, double gravity, int64_t utime) {
  ImuReading r;
  r.utime = utime;
  r.angular_velocity = state.angular_velocity;
  r.linear_acceleration = specificForce(state, gravity);
  return r;
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

}  // namespace sim
}  // namespace livo
