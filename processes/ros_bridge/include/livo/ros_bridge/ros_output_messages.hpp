// The pipeline's outputs as ROS 1 messages, for RViz and ROS consumers:
//   odometry_t        -> nav_msgs/Odometry (header frame = the world frame, child = the body frame;
//                        pose covariance as ROS orders and frames it, twist in the body frame)
//                        and geometry_msgs/TransformStamped (world -> body, for /tf)
//   registered_scan_t -> sensor_msgs/PointCloud2 in the world frame, stamped at the sweep end:
//                        x y z intensity time (float32, time = seconds after the sweep's start) ring (int16)
//   colored_cloud_t   -> sensor_msgs/PointCloud2 in the world frame: x y z (float32) rgb (float32
//                        holding 0x00RRGGBB, the packing RViz's RGB8 colour transformer and PCL read)
// LCM utime (microseconds) -> ros::Time; the project's quaternions (w, x, y, z) -> ROS's (x, y, z, w).
#pragma once

#include <cstdint>

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/PointCloud2.h>

#include "livo/colored_cloud_t.hpp"
#include "livo/odometry_t.hpp"
#include "livo/registered_scan_t.hpp"
#include "livo/ros_bridge/ros_bridge_config.hpp"

namespace livo::ros_bridge {

/// Microseconds since the epoch -> ros::Time. Throws std::invalid_argument for a negative stamp
/// (ROS 1 time is unsigned).
ros::Time rosTime(int64_t utime);

/// odometry_t -> nav_msgs/Odometry. The covariance of [rotation (right perturbation, body);
/// position (world)] becomes ROS's [position; rotation about the world axes], both in the world
/// frame; the twist is the body's (velocity rotated into the body frame, with its covariance; the
/// angular rate's covariance is not known and left zero).
nav_msgs::Odometry odometryToRos(const odometry_t& odometry, const RosFrames& frames);

/// The odometry's pose as the transform world -> body (for /tf).
geometry_msgs::TransformStamped odometryTransform(const odometry_t& odometry, const RosFrames& frames);

sensor_msgs::PointCloud2 registeredScanToRos(const registered_scan_t& scan, const RosFrames& frames);

sensor_msgs::PointCloud2 colouredCloudToRos(const colored_cloud_t& cloud, const RosFrames& frames);

}  // namespace livo::ros_bridge
