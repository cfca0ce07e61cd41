// Differential-drive wheel encoder: left/right contact-point speeds of the wheel base frame B
// from the body motion, with per-wheel scale error and white noise.
#pragma once

#include "livo/sensor_rig.hpp"
#include "livo/sim/random.hpp"
#include "livo/sim/sensor_data.hpp"
#include "livo/sim/trajectory.hpp"

namespace livo::sim {

/// Exact wheel speeds: v_B (forward, in B) -/+ yaw rate of B * track / 2.
WheelReading idealWheelReading(const BodyState& state, const WheelRig& rig, int64_t utime);

class WheelNoise {
 public:
  WheelNoise(const WheelRig& rig, double left_scale, double right_scale, Random rng)
      : rig_(rig), left_scale_(left_scale), right_scale_(right_scale), rng_(rng) {}
  void apply(WheelReading* r) {
    r->left_speed = r->left_speed * left_scale_ + rig_.speed_noise_std * rng_.normal();
    r->right_speed = r->right_speed * right_scale_ + rig_.speed_noise_std * rng_.normal();
  }

 private:
  WheelRig rig_;
  double left_scale_, right_scale_;
  Random rng_;
};

}  // namespace livo::sim
