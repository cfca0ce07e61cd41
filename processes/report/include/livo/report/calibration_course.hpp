// The sensors' calibration as lio's filter estimated it over the run (lio's calibration.csv, a row
// per second of sensor time): the "Calibration" section of report.md.
#pragma once

#include <string>
#include <vector>

namespace livo::report {

struct CalibrationRow {
  double t_s = 0.0;
  double lidar_time_shift_ms = 0.0, lidar_time_shift_std_ms = 0.0;
  double lidar_rot_deg[3] = {0, 0, 0}, lidar_rot_std_deg[3] = {0, 0, 0};
  double camera_time_shift_ms = 0.0, camera_time_shift_std_ms = 0.0;
  double camera_rot_deg[3] = {0, 0, 0}, camera_rot_std_deg[3] = {0, 0, 0};
  double camera_lidar_rot_deg[3] = {0, 0, 0};
};

/// Reads calibration.csv (its header names the columns); throws std::runtime_error naming the file
/// on a malformed one.
std::vector<CalibrationRow> readCalibrationCsv(const std::string& path);

/// The section: the estimate every 10 s and at the end, against the rig's values.
std::string calibrationMarkdown(const std::vector<CalibrationRow>& rows);

}  // namespace livo::report
