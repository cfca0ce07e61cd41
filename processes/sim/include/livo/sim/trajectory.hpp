// Body (= IMU frame I) motion with exact derivatives: pose, world velocity and acceleration and
// body angular rate at any time, so IMU samples can be computed exactly.
#pragma once

#include <limits>

#include "livo/so3.hpp"

namespace livo::sim {

struct BodyState {
  Pose3 T_W_I = Pose3::Identity();
  Vec3 velocity = Vec3::Zero();          // W_v_I, m/s
  Vec3 acceleration = Vec3::Zero();      // W_a_I, m/s^2 (kinematic, gravity not included)
  Vec3 angular_velocity = Vec3::Zero();  // I_w_WI, rad/s, body frame
};

class BodyTrajectory {
 public:
  virtual ~BodyTrajectory() = default;
  /// State at t seconds after the trajectory's start.
  virtual BodyState at(double t) const = 0;
  /// Seconds of motion available (infinite for procedural trajectories).
  virtual double duration() const { return std::numeric_limits<double>::infinity(); }
};

/// Specific force and angular rate an ideal IMU at the body origin measures.
inline Vec3 specificForce(const BodyState& s, double gravity) {
  return s.T_W_I.linear().transpose() * (s.acceleration + Vec3(0.0, 0.0, gravity));
}

}  // namespace livo::sim
