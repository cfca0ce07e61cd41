#include "livo/start_state_prior.hpp"

#include "livo/time.hpp"

namespace livo {

std::vector<ImuSample> imuStartWindow(const std::deque<ImuSample>& imu, int64_t t_end, double window_s) {
  std::vector<ImuSample> window;
  for (const ImuSample& s : imu)
    if (s.utime <= t_end && s.utime >= t_end - toUtime(window_s)) window.push_back(s);
  return window;
}

bool startWindowFilled(const std::vector<ImuSample>& window, double window_s) {
  return window.size() >= 2 && toSeconds(window.back().utime - window.front().utime) >= 0.8 * window_s;
}

StartStateSigmas restStartSigmas(const ImuInitOptions& init) {
  return {init.static_rot_std, init.static_vel_std, kRestGyroBiasStd, init.accel_bias_std};
}

StartStateSigmas movingStartSigmas(const ImuInitOptions& init) {
  return {init.moving_rot_std, init.moving_vel_std, init.moving_gyro_bias_std, init.accel_bias_std};
}

Mat6 startPoseInformation(double roll_pitch_std, double yaw_std, double pos_std) {
  Mat6 info = Mat6::Zero();
  info(0, 0) = info(1, 1) = 1.0 / (roll_pitch_std * roll_pitch_std);
  info(2, 2) = 1.0 / (yaw_std * yaw_std);
  info.bottomRightCorner<3, 3>() = Mat3::Identity() / (pos_std * pos_std);
  return info;
}

}  // namespace livo
