// Ouster sensor metadata JSON (firmware 2.x flat layout, and the SDK's nested layout with
// beam_intrinsics / lidar_data_format / config_params / imu_intrinsics / lidar_intrinsics).
#pragma once

#include <string>
#include <vector>

#include "livo/so3.hpp"

namespace livo::import {

struct OusterMetadata {
  std::string prod_line, prod_sn, firmware, lidar_mode;
  std::string udp_profile_lidar = "LEGACY", udp_profile_imu = "LEGACY";
  int columns_per_frame = 0, pixels_per_column = 0, columns_per_packet = 16;
  int column_window_first = 0, column_window_last = 0;
  double frames_per_second = 10.0;               // from lidar_mode "WxF"
  std::vector<double> beam_altitude_angles_deg;  // one per beam, top beam first
  std::vector<double> beam_azimuth_angles_deg;
  double lidar_origin_to_beam_origin_mm = 0.0;
  Eigen::Matrix4d beam_to_lidar = Eigen::Matrix4d::Identity();    // mm
  Eigen::Matrix4d lidar_to_sensor = Eigen::Matrix4d::Identity();  // mm
  Eigen::Matrix4d imu_to_sensor = Eigen::Matrix4d::Identity();    // mm
  int udp_port_lidar = 7502, udp_port_imu = 7503;
};

/// Throws std::runtime_error naming the file and the missing or malformed key.
OusterMetadata readOusterMetadata(const std::string& path);

}  // namespace livo::import
