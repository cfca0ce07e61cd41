#include "livo/trajectory_io.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>

namespace livo {

namespace {

std::vector<double> parseNumbers(const std::string& path, int line_no, const std::string& line) {
  std::vector<double> v;
  const char* p = line.c_str();
  while (*p) {
    while (*p == ' ' || *p == '\t' || *p == ',' || *p == '\r') ++p;
    if (!*p) break;
    char* end = nullptr;
    errno = 0;
    const double x = std::strtod(p, &end);
    if (end == p) {
      std::string field(p);
      field = field.substr(0, field.find_first_of(" \t,"));
      throw TrajectoryError(path + ":" + std::to_string(line_no) + ": '" + field + "' is not a number");
    }
    v.push_back(x);
    p = end;
  }
  return v;
}

Pose3 poseFromTranslationQuat(double x, double y, double z, double qw, double qx, double qy, double qz,
                              const std::string& path, int line_no) {
  Quat q(qw, qx, qy, qz);
  const double n = q.norm();
  if (!(n > 0.5 && n < 1.5) || !std::isfinite(x + y + z))
    throw TrajectoryError(path + ":" + std::to_string(line_no) + ": invalid pose (quaternion norm " +
                          std::to_string(n) + ")");
  Pose3 T = Pose3::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Vec3(x, y, z);
  return T;
}

void requireColumns(const std::vector<double>& v, size_t n, const std::string& path, int line_no, const char* fmt) {
  if (v.size() < n)
    throw TrajectoryError(path + ":" + std::to_string(line_no) + ": expected " + std::to_string(n) + " numbers (" +
                          fmt + "), got " + std::to_string(v.size()));
}

}  // namespace

void readNumericRows(const std::string& path, const std::function<void(int, const std::vector<double>&)>& row) {
  std::ifstream in(path);
  if (!in) throw TrajectoryError(path + ": cannot open");
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    row(line_no, parseNumbers(path, line_no, line));
  }
}

Trajectory readTum(const std::string& path) {
  Trajectory t;
  readNumericRows(path, [&](int ln, const std::vector<double>& v) {
    if (v.size() != 8) requireColumns(v, 8, path, ln, "t x y z qx qy qz qw");
    if (v.size() > 8)
      throw TrajectoryError(path + ":" + std::to_string(ln) + ": expected 8 numbers (TUM), got " +
                            std::to_string(v.size()));
    t.push_back({v[0], poseFromTranslationQuat(v[1], v[2], v[3], v[7], v[4], v[5], v[6], path, ln)});
  });
  return t;
}

void writeTum(const std::string& path, const Trajectory& trajectory) {
  std::ofstream out(path);
  if (!out) throw TrajectoryError(path + ": cannot write");
  out << "# timestamp tx ty tz qx qy qz qw\n" << std::fixed;
  for (const auto& s : trajectory) {
    Quat q(s.pose.linear());
    q.normalize();
    const Vec3& p = s.pose.translation();
    out << std::setprecision(9) << s.stamp << std::setprecision(9) << ' ' << p.x() << ' ' << p.y() << ' ' << p.z()
        << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w() << '\n';
  }
  if (!out) throw TrajectoryError(path + ": write failed");
}

Trajectory readKittiPoses(const std::string& path, const std::string& times_path) {
  Trajectory t;
  readNumericRows(path, [&](int ln, const std::vector<double>& v) {
    if (v.size() != 12)
      throw TrajectoryError(path + ":" + std::to_string(ln) + ": expected 12 numbers (KITTI 3x4 pose), got " +
                            std::to_string(v.size()));
    // Kept as written: KITTI rotations carry ~7 digits and are off SO(3) by ~1e-7; evaluation
    // tools (evo, the devkit) use them as they are, and so do we.
    Pose3 T = Pose3::Identity();
    T.matrix().topRows<3>() = Eigen::Map<const Eigen::Matrix<double, 3, 4, Eigen::RowMajor>>(v.data());
    if (!T.matrix().allFinite()) throw TrajectoryError(path + ":" + std::to_string(ln) + ": pose is not finite");
    t.push_back({static_cast<double>(t.size()), T});
  });
  if (!times_path.empty()) {
    std::vector<double> stamps;
    readNumericRows(times_path, [&](int ln, const std::vector<double>& v) {
      if (v.size() != 1) throw TrajectoryError(times_path + ":" + std::to_string(ln) + ": expected one time per line");
      stamps.push_back(v[0]);
    });
    if (stamps.size() != t.size())
      throw TrajectoryError(times_path + ": " + std::to_string(stamps.size()) + " times for " +
                            std::to_string(t.size()) + " poses in " + path);
    for (size_t i = 0; i < t.size(); ++i) t[i].stamp = stamps[i];
  }
  return t;
}

Trajectory readEurocCsv(const std::string& path) {
  Trajectory t;
  readNumericRows(path, [&](int ln, const std::vector<double>& v) {
    requireColumns(v, 8, path, ln, "timestamp[ns], p_x, p_y, p_z, q_w, q_x, q_y, q_z");
    t.push_back({v[0] * 1e-9, poseFromTranslationQuat(v[1], v[2], v[3], v[4], v[5], v[6], v[7], path, ln)});
  });
  return t;
}

TrajectoryFormat detectTrajectoryFormat(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw TrajectoryError(path + ": cannot open");
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto v = parseNumbers(path, line_no, line);
    if (line.find(',') != std::string::npos) return TrajectoryFormat::kEurocCsv;
    if (v.size() == 12) return TrajectoryFormat::kKitti;
    if (v.size() == 8) return TrajectoryFormat::kTum;
    throw TrajectoryError(path + ":" + std::to_string(line_no) + ": cannot tell the format from " +
                          std::to_string(v.size()) + " numbers (TUM has 8, KITTI 12, EuRoC csv is comma separated)");
  }
  throw TrajectoryError(path + ": no poses");
}

Trajectory readTrajectory(const std::string& path) {
  switch (detectTrajectoryFormat(path)) {
    case TrajectoryFormat::kKitti: return readKittiPoses(path);
    case TrajectoryFormat::kEurocCsv: return readEurocCsv(path);
    case TrajectoryFormat::kTum: break;
  }
  return readTum(path);
}

}  // namespace livo
