// Smooth synthetic trajectories with known transforms, for the evaluator's tests.
#pragma once

#include <cmath>
#include <random>

#include "livo/so3.hpp"
#include "livo/trajectory_io.hpp"

namespace livo {
namespace fixtures {

/// A 3-D figure-of-eight-like path (about 60 x 40 x 6 m) with a yaw following the direction of
/// travel plus roll/pitch wobble: `n` poses at `rate_hz` from `t0`.
inline Trajectory wigglyTrajectory(size_t n, double rate_hz = 10.0, double t0 = 1000.0) {
  Trajectory t;
  for (size_t i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / rate_hz;
    const Vec3 p(30.0 * std::sin(0.05 * s), 20.0 * std::sin(0.1 * s), 3.0 * std::sin(0.21 * s));
    const Vec3 v(1.5 * std::cos(0.05 * s), 2.0 * std::cos(0.1 * s), 0.63 * std::cos(0.21 * s));
    const double yaw = std::atan2(v.y(), v.x());
    Pose3 T = Pose3::Identity();
    T.linear() = so3::Exp(Vec3(0, 0, yaw)) * so3::Exp(Vec3(0.1 * std::sin(0.3 * s), 0.05 * std::cos(0.2 * s), 0));
    T.translation() = p;
    t.push_back({t0 + s, T});
  }
  return t;
}

/// Straight path along x, 1 m between poses, constant orientation; stamps 0.1 s apart.
inline Trajectory straightTrajectory(size_t n) {
  Trajectory t;
  for (size_t i = 0; i < n; ++i) {
    Pose3 T = Pose3::Identity();
    T.translation() = Vec3(static_cast<double>(i), 0, 0);
    t.push_back({0.1 * static_cast<double>(i), T});
  }
  return t;
}

/// Every pose moved by T on the left (a change of world frame) and positions scaled about the origin first.
inline Trajectory transformed(const Trajectory& in, const Pose3& T, double scale = 1.0) {
  Trajectory out = in;
  for (auto& s : out) {
    Pose3 scaled = s.pose;
    scaled.translation() *= scale;
    s.pose = T * scaled;
  }
  return out;
}

inline Pose3 somePose() {
  Pose3 T = Pose3::Identity();
  T.linear() = so3::Exp(Vec3(0.3, -1.1, 2.0));
  T.translation() = Vec3(12.0, -7.5, 3.25);
  return T;
}

}  // namespace fixtures
}  // namespace livo
