// Ouster pcap captures with their metadata JSON -> LCM log. LiDAR packets (UDP port
// udp_port_lidar) are grouped by frame id into sweeps; every pixel with a return becomes a point
// in the sensor frame (the Ouster "os_sensor" frame, the one ROS drivers publish), with its
// column's timestamp as per-point time and its beam (0 = top beam, the driver's row order) as
// ring. IMU packets (udp_port_imu) become imu_t in the IMU frame (g -> m/s^2, deg/s -> rad/s),
// stamped by their gyro timestamp. The LiDAR-to-IMU extrinsic goes into the metadata.
//
// Geometry (Ouster firmware 2.x sensor docs), for beam i of the column with measurement id m:
//   theta_e = 2 pi (1 - m / columns_per_frame), theta_a = -2 pi az_i / 360, phi = 2 pi alt_i / 360
//   n = |beam_to_lidar translation in x, z| (lidar_origin_to_beam_origin_mm)
//   x = (r - n) cos(theta_e + theta_a) cos(phi) + n cos(theta_e)
//   y = (r - n) sin(theta_e + theta_a) cos(phi) + n sin(theta_e)
//   z = (r - n) sin(phi) + beam_to_lidar z
// in the LiDAR frame (mm), then lidar_to_sensor_transform.
#pragma once

#include <string>

#include "livo/import/channel_names.hpp"
#include "livo/import/import_report.hpp"
#include "livo/import/ouster_metadata.hpp"
#include "livo/import/sorted_log_writer.hpp"

namespace livo::import {

struct OusterImportOptions {
  ChannelNames channels;
  std::string metadata_file;        // "" = <pcap without extension>.json, else the only .json beside it
  bool keep_partial_sweeps = true;  // sweeps missing packets (e.g. the capture's first and last)
  bool progress = true;
};

void importOuster(const std::string& pcap, const OusterImportOptions& options, SortedLogWriter& writer,
                  ImportReport& report);

/// The metadata file used for `pcap` when none is given; "" if none is found.
std::string findOusterMetadata(const std::string& pcap);

}  // namespace livo::import
