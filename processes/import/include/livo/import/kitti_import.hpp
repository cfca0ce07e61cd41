// KITTI folders -> LCM log. Three layouts, told apart by what the folder holds:
//  - raw drive (2011_09_26_drive_XXXX_sync or _extract): velodyne_points/data/*.bin|*.txt with
//    timestamps.txt [+ timestamps_start.txt, timestamps_end.txt] -> LIDAR; oxts/data/*.txt with
//    timestamps.txt (10 Hz synced or 100 Hz unsynced) -> IMU and GROUND_TRUTH; image_02 ->
//    CAMERA, image_03 -> CAMERA_RIGHT (PNG kept compressed).
//  - odometry sequence (dataset/sequences/XX): velodyne/*.bin with times.txt -> LIDAR, and
//    poses/XX.txt (or --poses) -> GROUND_TRUTH, moved into the LiDAR frame with calib.txt's Tr.
//  - a bare folder of scans (*.bin in it or in velodyne/), no stamps: stamped at --lidar-rate
//    from 0 s (said in a note).
// Sweep start: timestamps_start.txt where it exists, else the stamp (the forward-facing instant,
// mid-sweep) minus half the sweep duration. See kitti_velodyne.hpp for per-point times and rings.
#pragma once

#include <string>

#include "livo/import/channel_names.hpp"
#include "livo/import/import_report.hpp"
#include "livo/import/kitti_velodyne.hpp"
#include "livo/import/sorted_log_writer.hpp"

namespace livo::import {

struct KittiImportOptions {
  ChannelNames channels;
  KittiPointFields point_fields = KittiPointFields::kAuto;
  double sweep_duration = 0.1;  // seconds, when timestamps_start/end do not give it
  double lidar_rate_hz = 10.0;  // stamps of a folder without timestamp files
  std::string poses_file;       // odometry ground truth (default: ../../poses/<seq>.txt)
  std::string times_file;       // odometry times.txt (default: beside velodyne/)
  bool progress = true;
};

void importKitti(const std::string& folder, const KittiImportOptions& options, SortedLogWriter& writer,
                 ImportReport& report);

/// "2011-09-26 13:02:25.964389445" -> nanoseconds since the epoch (read as UTC); throws
/// std::invalid_argument if malformed.
int64_t parseKittiTimestamp(const std::string& text);

}  // namespace livo::import
