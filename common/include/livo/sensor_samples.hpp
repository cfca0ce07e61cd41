// The sensor readings as the estimators take them (no LCM): IMU samples, wheel speeds and LiDAR
// sweeps with per-point times. livo/sensor_messages.hpp reads them from the messages.
#pragma once

#include <cstdint>
#include <vector>

#include "livo/so3.hpp"

namespace livo {

/// One IMU sample in the body frame I: angular rate (rad/s) and specific force (m/s^2).
struct ImuSample {
  int64_t utime = 0;
  Vec3 gyro = Vec3::Zero();
  Vec3 accel = Vec3::Zero();
};

/// The two wheels' speeds of a differential drive.
struct WheelSample {
  int64_t utime = 0;
  double left_speed = 0.0;   // m/s
  double right_speed = 0.0;  // m/s
};

/// One LiDAR sweep: points in the LiDAR frame L with per-point time offsets.
struct LidarScan {
  int64_t utime = 0;               // sweep start, LiDAR clock (µs)
  double sweep_duration = 0.1;     // s; the scan ends at utime + max(sweep_duration, last offset)
  std::vector<Vec3> points;        // frame L
  std::vector<float> time_offset;  // s after utime, one per point
  std::vector<float> intensity;    // one per point (may be empty: zeros)
  std::vector<int16_t> ring;       // one per point (may be empty: no rings)
};

/// LiDAR-IMU extrinsic and time offset: p_I = T_I_L p_L; t_imu = t_lidar + time_offset_s.
struct LidarExtrinsics {
  Pose3 T_I_L = Pose3::Identity();
  double time_offset_s = 0.0;
};

}  // namespace livo
