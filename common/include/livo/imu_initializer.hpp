// IMU initialisation: the first state and covariance of the filter from a window of IMU samples.
//  - static start: the body is still; gravity direction from the mean specific force, gyro bias
//    from the mean rate, the accelerometer's bias along "up" from the mean specific force's
//    magnitude against the rig's gravity (at rest it must equal it: the excess is the sensor's
//    error along that axis, a scale error or a bias, which no later measurement separates from
//    a vertical acceleration until the LiDAR sees the height), small initial covariance;
//  - moving start: no still window is needed; gravity magnitude from the rig, direction from the
//    averaged specific force, zero biases and velocity with a larger covariance.
// The world frame W is gravity-aligned (z up) with the body origin at the start and zero yaw.
#pragma once

#include <string>
#include <vector>

#include "livo/filter_state.hpp"
#include "livo/sensor_samples.hpp"

namespace livo {

struct ImuInitOptions {
  enum class Mode { kAuto, kStatic, kMoving };
  Mode mode = Mode::kAuto;     // auto: static if the window is still, moving otherwise
  double window_s = 0.5;       // IMU window collected before initialising
  double gravity = 9.81;       // m/s^2 (rig imu.gravity)
  double max_gyro_std = 0.02;  // rad/s: stillness test, per axis
  double max_accel_std = 0.1;  // m/s^2: stillness test, per axis
  // initial standard deviations, static start
  double static_rot_std = 0.01;        // rad, roll and pitch
  double static_vel_std = 0.01;        // m/s
  double accel_bias_std = 0.05;        // m/s^2 (both modes; static: across "up" only)
  double static_up_bias_floor = 2e-3;  // m/s^2, added to the mean's standard error along "up"
  double gravity_std = 1e-3;           // m/s^2 per axis
  // initial standard deviations, moving start
  double moving_rot_std = 0.1;         // rad, roll and pitch
  double moving_vel_std = 1.0;         // m/s
  double moving_gyro_bias_std = 0.01;  // rad/s
  double moving_gravity_std = 0.1;     // m/s^2 per axis
  // fixed gauge: yaw and position at the start
  double yaw_std = 1e-4;  // rad
  double pos_std = 1e-4;  // m
};

struct ImuInitResult {
  bool ok = false;
  bool static_start = false;
  FilterState state;
  Mat18 covariance = Mat18::Identity();
  ImuSample last;  // the last sample of the window: the state refers to its time
  std::string message;
};

/// True if the samples' per-axis standard deviations are within the stillness limits.
bool isStill(const std::vector<ImuSample>& window, const ImuInitOptions& opts);

/// Initialises from a window (time-ordered, at least two samples spanning window_s for auto
/// and static; moving mode accepts any non-empty window). Fails (ok = false) for a static
/// request on a moving window or a degenerate specific force.
ImuInitResult initializeImu(const std::vector<ImuSample>& window, const ImuInitOptions& opts);

}  // namespace livo
