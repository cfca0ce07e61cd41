#include "livo/lio/calibration_report.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace livo::lio {

namespace {
constexpr double kDeg = 180.0 / M_PI;

SensorCalibrationChange change(const SensorCalibration& c, const Pose3& rig, const StateCovariance& P, int block) {
  SensorCalibrationChange s;
  s.rotation_deg = so3::Log(Mat3(rig.linear().transpose() * c.rot)) * kDeg;
  s.translation = c.pos - rig.translation();
  s.time_shift_ms = c.dt * 1e3;
  const auto d = P.diagonal();
  for (int i = 0; i < 3; ++i) {
    s.rotation_std_deg[i] = std::sqrt(std::max(0.0, d[block + FilterState::kCalRot + i])) * kDeg;
    s.translation_std[i] = std::sqrt(std::max(0.0, d[block + FilterState::kCalPos + i]));
  }
  s.time_shift_std_ms = std::sqrt(std::max(0.0, d[block + FilterState::kCalDt])) * 1e3;
  return s;
}

void put(std::ostream& os, const char* name, const SensorCalibrationChange& s) {
  os << name << " rotation (" << s.rotation_deg.x() << ", " << s.rotation_deg.y() << ", " << s.rotation_deg.z()
     << ") deg +/- (" << s.rotation_std_deg.x() << ", " << s.rotation_std_deg.y() << ", " << s.rotation_std_deg.z()
     << "), translation (" << 1e3 * s.translation.x() << ", " << 1e3 * s.translation.y() << ", "
     << 1e3 * s.translation.z() << ") mm +/- (" << 1e3 * s.translation_std.x() << ", " << 1e3 * s.translation_std.y()
     << ", " << 1e3 * s.translation_std.z() << "), time shift " << s.time_shift_ms << " +/- " << s.time_shift_std_ms
     << " ms";
}

void row(std::ostream& os, const SensorCalibrationChange& s) {
  for (int i = 0; i < 3; ++i) os << ',' << s.rotation_deg[i];
  for (int i = 0; i < 3; ++i) os << ',' << s.translation[i];
  os << ',' << s.time_shift_ms;
  for (int i = 0; i < 3; ++i) os << ',' << s.rotation_std_deg[i];
  for (int i = 0; i < 3; ++i) os << ',' << s.translation_std[i];
  os << ',' << s.time_shift_std_ms;
}

void pose(std::ostream& os, const Pose3& T) {
  // rpy_deg as the rig states it (R = Rz(yaw) Ry(pitch) Rx(roll)), so that the overlay's keys
  // replace the rig's one by one
  const Mat3 R = T.linear();
  const double roll = std::atan2(R(2, 1), R(2, 2)) * kDeg, pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0)) * kDeg,
               yaw = std::atan2(R(1, 0), R(0, 0)) * kDeg;
  os << "{translation: [" << T.translation().x() << ", " << T.translation().y() << ", " << T.translation().z()
     << "], rpy_deg: [" << roll << ", " << pitch << ", " << yaw << "]}";
}
}  // namespace

CalibrationEstimate calibrationAgainstRig(const FilterState& x, const StateCovariance& P, const Pose3& T_I_L_rig,
                                          const Pose3& T_I_C_rig) {
  CalibrationEstimate e;
  e.lidar = change(x.lidar, T_I_L_rig, P, FilterState::kLidar);
  e.camera = change(x.camera, T_I_C_rig, P, FilterState::kCamera);
  const Mat3 R_LC_rig = T_I_L_rig.linear().transpose() * T_I_C_rig.linear();
  const Mat3 R_LC = x.lidar.rot.transpose() * x.camera.rot;
  e.camera_lidar_rotation_deg = so3::Log(Mat3(R_LC_rig.transpose() * R_LC)) * kDeg;
  return e;
}

std::string describe(const CalibrationEstimate& e, bool with_camera) {
  std::ostringstream os;
  os << std::setprecision(3);
  put(os, "LiDAR", e.lidar);
  if (with_camera) {
    os << "; ";
    put(os, "camera", e.camera);
    const Vec3& r = e.camera_lidar_rotation_deg;
    os << "; camera against the LiDAR turned by (" << r.x() << ", " << r.y() << ", " << r.z() << ") deg from the rig's";
  }
  return os.str();
}

std::string describeImuIntrinsics(const ImuIntrinsics& k, const ImuIntrinsics::Covariance& P) {
  std::ostringstream os;
  os << std::setprecision(3) << "IMU axes:";
  auto put = [&](const char* what, int offset, int n, double unit, const char* unit_name) {
    os << " " << what << " (";
    for (int i = 0; i < n; ++i) os << (i ? ", " : "") << k.value[offset + i] * unit;
    os << ") +/- (";
    for (int i = 0; i < n; ++i) os << (i ? ", " : "") << std::sqrt(std::max(0.0, P(offset + i, offset + i))) * unit;
    os << ") " << unit_name;
  };
  put("gyro scale", ImuIntrinsics::kGyroScale, 3, 100.0, "%,");
  put("off-diagonal", ImuIntrinsics::kGyroCross, 6, 1e3, "mrad;");
  put("accel scale", ImuIntrinsics::kAccelScale, 3, 100.0, "%,");
  put("off-diagonal", ImuIntrinsics::kAccelCross, 6, 1e3, "mrad");
  return os.str();
}

std::string calibrationCsvHeader() {
  std::string h = "t_s";
  for (const char* s : {"lidar", "camera"}) {
    const std::string p = s;
    h += "," + p + "_rot_x_deg," + p + "_rot_y_deg," + p + "_rot_z_deg," + p + "_x_m," + p + "_y_m," + p + "_z_m," + p +
         "_time_shift_ms," + p + "_rot_x_std_deg," + p + "_rot_y_std_deg," + p + "_rot_z_std_deg," + p + "_x_std_m," +
         p + "_y_std_m," + p + "_z_std_m," + p + "_time_shift_std_ms";
  }
  return h + ",camera_lidar_rot_x_deg,camera_lidar_rot_y_deg,camera_lidar_rot_z_deg\n";
}

std::string calibrationCsvRow(double t, const CalibrationEstimate& e) {
  std::ostringstream os;
  os << std::setprecision(9) << t;
  row(os, e.lidar);
  row(os, e.camera);
  for (int i = 0; i < 3; ++i) os << ',' << e.camera_lidar_rotation_deg[i];
  os << '\n';
  return os.str();
}

std::string calibrationOverlay(const FilterState& x, double lidar_offset_rig_s, double camera_offset_rig_s,
                               bool with_camera, const CalibrationEstimate& e) {
  std::ostringstream os;
  os << std::setprecision(9);
  os << "# The rig as livo-lio estimated it (its filter's calibration at the end of the run), a config\n"
        "# overlay: scripts/run_pipeline.sh --overlay calibration.yaml, or copy the values into the rig.\n"
     << "# " << describe(e, with_camera) << "\n"
     << "rig:\n  lidar:\n    T_I_L: ";
  pose(os, x.lidar.pose());
  os << "\n";
  if (with_camera) {
    os << "  camera:\n    T_I_C: ";
    pose(os, x.camera.pose());
    os << "\n    time_offset_s: " << camera_offset_rig_s + x.camera.dt << "\n";
  }
  os << "lio:\n  lidar_time_offset_s: " << lidar_offset_rig_s + x.lidar.dt << "\n";
  return os.str();
}

}  // namespace livo::lio
