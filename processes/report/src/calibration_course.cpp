#include "livo/report/calibration_course.hpp"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <stdexcept>

namespace livo::report {

namespace {
std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  std::string f;
  while (std::getline(s, f, ',')) out.push_back(f);
  return out;
}

std::string vec(const double* v, int digits) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(digits) << "(" << v[0] << ", " << v[1] << ", " << v[2] << ")";
  return os.str();
}
}  // namespace

std::vector<CalibrationRow> readCalibrationCsv(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot read");
  std::string line;
  if (!std::getline(f, line)) return {};
  std::map<std::string, size_t> col;
  const std::vector<std::string> header = split(line);
  for (size_t i = 0; i < header.size(); ++i) col[header[i]] = i;
  auto index = [&](const std::string& name) {
    auto it = col.find(name);
    if (it == col.end()) throw std::runtime_error(path + ": no column " + name);
    return it->second;
  };
  std::vector<CalibrationRow> rows;
  int n = 1;
  while (std::getline(f, line)) {
    ++n;
    if (line.empty()) continue;
    const std::vector<std::string> v = split(line);
    if (v.size() != header.size())
      throw std::runtime_error(path + ":" + std::to_string(n) + ": wrong number of fields");
    auto get = [&](const std::string& name) {
      try {
        return std::stod(v[index(name)]);
      } catch (const std::invalid_argument&) {
        throw std::runtime_error(path + ":" + std::to_string(n) + ": " + name + " is not a number");
      }
    };
    CalibrationRow r;
    r.t_s = get("t_s");
    r.lidar_time_shift_ms = get("lidar_time_shift_ms");
    r.lidar_time_shift_std_ms = get("lidar_time_shift_std_ms");
    r.camera_time_shift_ms = get("camera_time_shift_ms");
    r.camera_time_shift_std_ms = get("camera_time_shift_std_ms");
    for (int i = 0; i < 3; ++i) {
      const std::string a(1, "xyz"[i]);
      r.lidar_rot_deg[i] = get("lidar_rot_" + a + "_deg");
      r.lidar_rot_std_deg[i] = get("lidar_rot_" + a + "_std_deg");
      r.camera_rot_deg[i] = get("camera_rot_" + a + "_deg");
      r.camera_rot_std_deg[i] = get("camera_rot_" + a + "_std_deg");
      r.camera_lidar_rot_deg[i] = get("camera_lidar_rot_" + a + "_deg");
    }
    rows.push_back(r);
  }
  return rows;
}

std::string calibrationMarkdown(const std::vector<CalibrationRow>& rows) {
  std::ostringstream md;
  md << "## Calibration\n\n";
  if (rows.empty()) {
    md << "lio wrote no estimate (`calibration.csv` is empty).\n\n";
    return md.str();
  }
  md << "The sensors' calibration in lio's filter (`calibration.csv`, a row per second; `calibration.yaml` holds the "
        "rig as estimated at the end, an overlay for `run_pipeline.sh --overlay`), against the rig's values: the "
        "LiDAR's time shift, the camera's rotation (its own, and against the LiDAR's, in the camera frame) and time "
        "shift, each with the filter's 1-sigma. A part the filter holds at the rig's value shows 0 +/- 0.\n\n";
  md << "| t s | LiDAR time shift ms | camera rotation deg | camera against the LiDAR deg | camera time shift ms |\n";
  md << "| --- | --- | --- | --- | --- |\n";
  double next = 0.0;
  for (size_t i = 0; i < rows.size(); ++i) {
    const CalibrationRow& r = rows[i];
    const bool last = i + 1 == rows.size();
    if (r.t_s + 1e-9 < next && !last) continue;
    next = std::floor(r.t_s / 10.0 + 1.0) * 10.0;
    md << std::fixed << "| " << std::setprecision(0) << r.t_s << " | " << std::setprecision(2) << r.lidar_time_shift_ms
       << " +/- " << r.lidar_time_shift_std_ms << " | " << vec(r.camera_rot_deg, 3) << " +/- "
       << vec(r.camera_rot_std_deg, 3) << " | " << vec(r.camera_lidar_rot_deg, 3) << " | " << std::setprecision(2)
       << r.camera_time_shift_ms << " +/- " << r.camera_time_shift_std_ms << " |\n";
  }
  md << "\n";
  return md.str();
}

}  // namespace livo::report
