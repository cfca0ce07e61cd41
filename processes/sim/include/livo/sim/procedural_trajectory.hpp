// A procedural body trajectory: a smooth path, small sinusoidal shake in position and attitude,
// a still start with a smooth (C3) speed ramp, and an attitude that either follows the heading (walks)
// or aligns the body z axis with the thrust (multirotor flight). Cars: car_trajectory.hpp. Every derivative is
// analytic, so IMU samples are exact.
#pragma once

#include <memory>
#include <vector>

#include "livo/sim/paths.hpp"
#include "livo/sim/trajectory.hpp"

namespace livo::sim {

struct Sinusoid {
  double amplitude = 0.0;     // m or rad
  double frequency_hz = 1.0;  // per second of path time
  double phase = 0.0;         // rad
};

/// Shake added as a function of path time (so it freezes when the body stands still).
struct MotionShake {
  std::vector<Sinusoid> position[3];  // world x, y, z, metres
  std::vector<Sinusoid> attitude[3];  // roll, pitch, yaw on top of the base attitude, rad
};

enum class AttitudeMode {
  kFollowHeading,  // yaw along the horizontal velocity of the path (no side slip at the body origin)
  kThrustAligned,  // body z along acceleration + gravity, yaw from yaw_rate / yaw_wave
};

struct ProceduralTrajectoryOptions {
  AttitudeMode attitude = AttitudeMode::kFollowHeading;
  double start_still_s = 2.0;  // stand still this long
  double ramp_s = 2.0;         // then reach full speed over this long
  MotionShake shake;
  double gravity = 9.81;  // for kThrustAligned
  double yaw_rate = 0.0;  // rad per second of path time (kThrustAligned)
  Sinusoid yaw_wave;      // added to the yaw (kThrustAligned)
};

/// Built-in shake of a handheld walk, a car and a multirotor, times `scale`.
MotionShake handheldShake(double scale);
MotionShake carShake(double scale);
MotionShake flightShake(double scale);

/// Sum of sinusoids at path time s: value and its first three derivatives in s.
void sumOfSinusoids(const std::vector<Sinusoid>& waves, double s, double out[4]);

struct PathTimeWarp {
  double s, d1, d2, d3;  // path time and its derivatives in t
};
/// Path time at time t: still for start_still_s, then a smooth (C3) ramp to full speed over ramp_s.
PathTimeWarp rampedPathTime(double t, double start_still_s, double ramp_s);

class ProceduralTrajectory : public BodyTrajectory {
 public:
  ProceduralTrajectory(std::unique_ptr<Path> path, const ProceduralTrajectoryOptions& options);
  BodyState at(double t) const override;

 private:
  std::unique_ptr<Path> path_;
  ProceduralTrajectoryOptions options_;
};

}  // namespace livo::sim
