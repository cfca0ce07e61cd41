// When a LiDAR sweep starts and ends on the IMU clock, from its stamp, its sweep_duration and its
// points' time offsets. The one definition livo-lio and livo-lio-graph share: they run in place of
// each other, so they must agree on what a sweep covers and when the IMU has passed it.
#pragma once

#include <cstdint>

#include "livo/sensor_samples.hpp"

namespace livo {

/// The longest sweep believed (s): a point time offset or a sweep_duration beyond it is garbage (a
/// corrupted or misread field), not a long sweep. The IMU steps kept for undistortion span it too.
inline constexpr double kMaxSweepDurationS = 1.0;

/// The sweep's end in seconds after its stamp (LiDAR clock): the largest of
///   - scan.sweep_duration, when it is finite and in (0, kMaxSweepDurationS], and
///   - the points' time offsets that are finite and in [0, kMaxSweepDurationS];
/// 0 when there is neither (an empty sweep without a valid sweep_duration). Negative, non-finite
/// and too-large offsets do not move the end; rejecting those points is the caller's business.
double sweepEndOffset(const LidarScan& scan);

/// A sweep's span on the IMU clock, t_imu = t_lidar + lidar_time_offset_s.
struct SweepTiming {
  int64_t start_utime = 0;    // scan.utime + lidar_time_offset_s
  int64_t end_utime = 0;      // scan.utime + (lidar_time_offset_s + end_offset_s), rounded once
  double end_offset_s = 0.0;  // sweepEndOffset(scan): points with offsets in [0, end_offset_s] are in it
};

/// The sweep's start and end on the IMU clock (its end offset from sweepEndOffset).
SweepTiming sweepTiming(const LidarScan& scan, double lidar_time_offset_s);

}  // namespace livo
