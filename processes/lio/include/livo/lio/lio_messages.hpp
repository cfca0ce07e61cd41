// Conversions between the LCM messages and the LIO core's types.
#pragma once

#include <string>

#include "livo/filter_state_message.hpp"
#include "livo/imu_t.hpp"
#include "livo/keyframe_t.hpp"
#include "livo/lio/lio_estimator.hpp"
#include "livo/loop_correction_message.hpp"
#include "livo/odometry_t.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/registered_scan_t.hpp"
#include "livo/sensor_messages.hpp"
#include "livo/wheel_odometry_t.hpp"

namespace livo::lio {

// The sensor messages: livo/sensor_messages.hpp (fromMessage for imu_t, wheel_odometry_t and
// point_cloud_t); LOOP_CORRECTION: livo/loop_correction_message.hpp (shared with livo-lio-graph).

/// What the outputs take from an input sweep beyond its LidarScan (fromMessage keeps the rest).
struct SweepFormat {
  int8_t pattern = point_cloud_t::PATTERN_SPINNING;
  int16_t num_rings = 0;
};
inline SweepFormat sweepFormat(const point_cloud_t& m) { return {m.pattern, m.num_rings}; }

/// The output messages carry the frame they are in (epoch, correction_id).
odometry_t toOdometry(const ScanResult& r, const OdometryFrame& frame);
/// The undistorted sweep in frame "W": every point is expressed at the sweep end (the
/// message's utime, the odometry time), while cloud.utime is the sweep start in the IMU clock
/// (input utime + LiDAR time offset) and each point keeps its input time_offset, so
/// cloud.utime + time_offset is the point's capture time (what the colouring process uses to pick
/// images). cloud.sweep_duration, ring and intensity come from the input.
registered_scan_t toRegisteredScan(const ScanResult& r, const point_cloud_t& input, const OdometryFrame& frame);
/// The same from the input as the node keeps it: the sweep as fromMessage read it, and its format.
registered_scan_t toRegisteredScan(const ScanResult& r, const LidarScan& input, const SweepFormat& format,
                                   const OdometryFrame& frame);
/// The keyframe's downsampled body-frame cloud with the input intensities; time offsets zero
/// (the cloud is undistorted to the keyframe's utime).
keyframe_t toKeyframe(const Keyframe& k, int16_t num_rings, const OdometryFrame& frame);
/// STATE_PRIOR (camera hand-off): the filter's state and covariance at `utime` (where propagateTo
/// moved it) with its body rate, in the frame it is in, as request `request_id` of node `sender`.
filter_state_t toStatePrior(const LioEstimator& lio, int64_t utime, int64_t request_id, const std::string& sender);

}  // namespace livo::lio
