// One LiDAR sweep as the core sees it: points in the LiDAR frame L with per-point time offsets.
#pragma once

#include <cstdint>
#include <vector>

#include "livo/so3.hpp"

namespace livo::lio {

struct LidarScan {
  int64_t utime = 0;             // sweep start, LiDAR clock (µs)
  double sweep_duration = 0.1;   // s; the scan ends at utime + max(sweep_duration, last offset)
  std::vector<Vec3> points;      // frame L
  std::vector<float> time_offset;// s after utime, one per point
  std::vector<float> intensity;  // one per point (may be empty: zeros)
};

/// LiDAR-IMU extrinsic and time offset: p_I = T_I_L p_L; t_imu = t_lidar + time_offset_s.
struct LidarExtrinsics {
  Pose3 T_I_L = Pose3::Identity();
  double time_offset_s = 0.0;
};

}  // namespace livo::lio
