// Trajectory files: TUM ("t x y z qx qy qz qw"), KITTI poses (12 numbers, 3x4 row-major, one per
// line, times from a separate file or the line index) and EuRoC/ASL ground-truth csv
// ("#timestamp [ns], p_x, p_y, p_z, q_w, q_x, q_y, q_z, ..."). Errors name the file and line.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "livo/so3.hpp"

namespace livo {

struct StampedPose {
  double stamp = 0.0;  // seconds (float64, as TUM files and evo use them)
  Pose3 pose = Pose3::Identity();
};
using Trajectory = std::vector<StampedPose>;

enum class TrajectoryFormat { kTum, kKitti, kEurocCsv };

class TrajectoryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

Trajectory readTum(const std::string& path);
void writeTum(const std::string& path, const Trajectory& trajectory);
/// KITTI poses, matrices kept exactly as written (not re-orthonormalised); `times_path` (KITTI
/// times.txt) gives stamps, else stamp = line index.
Trajectory readKittiPoses(const std::string& path, const std::string& times_path = "");
/// EuRoC/ASL ground-truth csv (nanosecond stamps, position, quaternion w x y z; extra columns ignored).
Trajectory readEurocCsv(const std::string& path);

/// Looks at the first data line: 12 numbers -> KITTI, a comma -> EuRoC csv, 8 numbers -> TUM.
TrajectoryFormat detectTrajectoryFormat(const std::string& path);
Trajectory readTrajectory(const std::string& path);

/// Reads whitespace/comma separated numeric rows, skipping blank lines and '#' comments.
/// Calls row(line_number, values) for each; throws TrajectoryError naming file and line if a
/// field is not a number.
void readNumericRows(const std::string& path, const std::function<void(int, const std::vector<double>&)>& row);

}  // namespace livo
