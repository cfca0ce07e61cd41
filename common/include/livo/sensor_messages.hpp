// The sensor messages read into the estimators' types (livo/sensor_samples.hpp).
#pragma once

#include <string>

#include "livo/imu_t.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/sensor_samples.hpp"
#include "livo/wheel_odometry_t.hpp"

namespace livo {

ImuSample fromMessage(const imu_t& m);
WheelSample fromMessage(const wheel_odometry_t& m);
/// A sweep in frame "L". False with the reason for inconsistent array sizes or another frame.
/// The rings are kept when the message has one per point.
bool fromMessage(const point_cloud_t& m, LidarScan* scan, std::string* why);

}  // namespace livo
