// The first state of a sliding window started from the IMU (livo-lio-graph, livo-vio-feature): the
// start-up window of IMU samples it is initialised from, and its priors, which hold the gauge (yaw
// and position) firmly and roll, pitch, velocity and biases with the initialisation's sigmas.
#pragma once

#include <cstdint>
#include <deque>
#include <vector>

#include "livo/imu_initializer.hpp"
#include "livo/sensor_samples.hpp"
#include "livo/so3.hpp"

namespace livo {

/// rad/s: the prior sigma of a gyro bias initialised at rest, where the bias is the mean rate of
/// the still window (about 0.1 deg/s: what that mean may be off by, and room for the bias to move).
constexpr double kRestGyroBiasStd = 0.002;

/// What an estimator reports while the start-up window is not yet filled.
constexpr const char* kWaitingForImuStartWindow = "waiting for the IMU initialisation window";

/// The IMU samples of the start-up window ending at t_end: those in [t_end - window_s, t_end].
std::vector<ImuSample> imuStartWindow(const std::deque<ImuSample>& imu, int64_t t_end, double window_s);

/// True if the start-up window can be initialised from: two samples or more, spanning at least
/// 80 % of window_s.
bool startWindowFilled(const std::vector<ImuSample>& window, double window_s);

/// The first state's prior sigmas.
struct StartStateSigmas {
  double rotation = 0.0;    // rad, roll and pitch
  double velocity = 0.0;    // m/s
  double gyro_bias = 0.0;   // rad/s
  double accel_bias = 0.0;  // m/s^2
};

/// After a start at rest: the static sigmas, kRestGyroBiasStd for the gyro bias.
StartStateSigmas restStartSigmas(const ImuInitOptions& init);

/// After a start in motion: the moving sigmas.
StartStateSigmas movingStartSigmas(const ImuInitOptions& init);

/// The first pose's information [dtheta (right), dp]: roll and pitch with sigma roll_pitch_std, the
/// gauge (yaw, position) held with yaw_std and pos_std. The information is on the body-frame
/// rotation while roll, pitch and yaw are world-frame angles: for a level start they coincide,
/// otherwise this is the usual approximation.
Mat6 startPoseInformation(double roll_pitch_std, double yaw_std, double pos_std);

}  // namespace livo
