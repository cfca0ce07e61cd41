// Topic maps and sensor conventions of public datasets recorded as ROS 1 bags.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "livo/import/point_cloud2_conversion.hpp"

namespace livo::import {

struct RosbagPreset {
  std::string name;
  std::string description;
  std::string imu_topic, lidar_topic, camera_topic, camera_right_topic, depth_topic, ground_truth_topic;
  std::string ground_truth_child_frame = "I";
  LidarStampConvention lidar_stamp = LidarStampConvention::kStart;
  double sweep_duration = 0.1;
  int num_rings = 0;
  /// Facts with no message type, copied into the summary and the sidecar (YAML values).
  std::vector<std::pair<std::string, std::string>> metadata;
  /// The dataset's calibration for a starter rig (--rig-out): the project's calibrated rig, and
  /// the extrinsics of the preset's LiDAR and camera topics (YAML as a rig writes them; "" unknown).
  std::string calibrated_rig;
  std::string T_I_L, T_I_C, extrinsics_source;
};

const std::vector<RosbagPreset>& rosbagPresets();
/// nullptr if unknown.
const RosbagPreset* findRosbagPreset(const std::string& name);

}  // namespace livo::import
