// Reads the `ros_bridge:` section of a project config (strict: unknown keys are errors) with the
// command line's flags over it, and a livo-import preset filling the topics left empty, in the
// order livo-import applies them: topics from the config, then the flags, then the preset; the
// LiDAR conventions from the preset, then the config, then the flags.
#pragma once

#include <iosfwd>
#include <optional>
#include <string>

#include "livo/config.hpp"
#include "livo/import/rosbag_import.hpp"

namespace livo::ros_bridge {

/// ROS frame names of the outputs.
struct RosFrames {
  std::string world = "world";  // the odometry frame W (nav_msgs/Odometry header, tf parent, clouds)
  std::string body = "body";    // the body I (Odometry child_frame_id, tf child)
};

/// ROS topics the outputs are published on ("" : that output is not published).
struct RosOutputTopics {
  std::string odometry = "/livo/odometry";                // nav_msgs/Odometry
  std::string registered_scan = "/livo/registered_scan";  // sensor_msgs/PointCloud2, world frame
  std::string colored_cloud = "/livo/colored_cloud";      // sensor_msgs/PointCloud2 with rgb, world frame
  bool tf = true;                                         // world -> body on /tf with each odometry
};

struct RosBridgeNodeOptions {
  std::string preset;  // a livo-import rosbag preset (ntu_viral, m2dgr), "" none
  /// ROS topics in and how they convert: livo-import rosbag's own options (topics, LiDAR stamp
  /// convention and sweep, IMU units, the LCM channels the sensors go out on).
  import::RosbagImportOptions input;
  RosFrames frames;
  RosOutputTopics outputs;
  // LCM channels the outputs come from
  std::string odometry_channel = "ODOMETRY";
  std::string registered_scan_channel = "REGISTERED_SCAN";
  std::string colored_cloud_channel = "COLORED_CLOUD";
  int imu_queue = 2000;   // ROS subscriber queue of the IMU topic (10 s at 200 Hz)
  int sensor_queue = 50;  // of each other input topic
};

/// The command line's values; empty / unset ones leave the config's.
struct RosBridgeFlags {
  std::string preset;
  std::string imu, lidar, camera, camera_right, depth, ground_truth, ground_truth_frame;
  std::string world_frame, body_frame;
  std::string lidar_stamp;  // start, end
  std::optional<double> sweep_duration;
  std::optional<int> lidar_rings;
};

/// Throws ConfigError naming the key (std::invalid_argument naming the flag) for an unknown key,
/// an out-of-range value, an unknown preset, or no input topic at all. The sensor channels
/// default to the rig's (`rig.channels`).
RosBridgeNodeOptions readRosBridgeNodeOptions(const Config& root, const RosBridgeFlags& flags = {});

/// The topics, channels and frames, for the log at start-up.
void printOptions(const RosBridgeNodeOptions& o, std::ostream& os);

}  // namespace livo::ros_bridge
