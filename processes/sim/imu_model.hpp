// IMU measurement model: exact specific force and angular rate plus white noise and bias random
// walks with the usual continuous-time parameters (discrete std = density / sqrt(dt); bias step
// std = random_walk * sqrt(dt)).
#pragma once

#include "livo/sensor_rig.hpp"
#include "random.hpp"
#include "sensor_data.hpp"
#include "trajectory.hpp"

namespace livo {
namespace sim {

/// Noise-free reading of an IMU at the body origin.
ImuReading idealImuReading(const BodyState& state, double gravity, int64_t utime);

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

}  // namespace sim
}  // namespace livo
