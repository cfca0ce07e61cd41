#include "livo/sim/calibration_errors.hpp"

#include <cmath>

#include "livo/sim/random.hpp"

namespace livo::sim {

namespace {

// Random stream of the calibration draws; each quantity is an index (a hash of its name).
const uint64_t kCalibrationStream = hashString("calibration_errors");

Pose3 mountedWith(const Pose3& T_I_X, const ExtrinsicError& e) {
  return e.isZero() ? T_I_X : Pose3(T_I_X * e.transform());
}

ExtrinsicError drawExtrinsic(const ExtrinsicError& sigma, uint64_t seed, const std::string& sensor) {
  ExtrinsicError e;
  e.translation = drawError(sigma.translation, seed, sensor + ".translation");
  e.rpy_deg = drawError(sigma.rpy_deg, seed, sensor + ".rpy_deg");
  return e;
}

}  // namespace

Pose3 ExtrinsicError::transform() const {
  const Vec3 rpy = rpy_deg * (M_PI / 180.0);
  Pose3 T = Pose3::Identity();
  T.linear() = (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
                Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()))
                   .toRotationMatrix();
  T.translation() = translation;
  return T;
}

bool CalibrationErrors::any() const {
  return !lidar.isZero() || !camera.isZero() || !wheel.isZero() || lidar_time_offset_s != 0.0 ||
         camera_time_offset_s != 0.0 || wheel_time_offset_s != 0.0;
}

SensorRig trueRig(const SensorRig& nominal, const CalibrationErrors& errors) {
  SensorRig rig = nominal;
  if (rig.lidar) rig.lidar->T_I_L = mountedWith(rig.lidar->T_I_L, errors.lidar);
  if (rig.camera) rig.camera->T_I_C = mountedWith(rig.camera->T_I_C, errors.camera);
  if (rig.wheel) rig.wheel->T_I_B = mountedWith(rig.wheel->T_I_B, errors.wheel);
  return rig;
}

double drawError(double sigma, uint64_t seed, const std::string& name) {
  if (sigma == 0.0) return 0.0;
  return sigma * Random(seed, kCalibrationStream, hashString(name.c_str())).normal();
}

Vec3 drawError(const Vec3& sigma, uint64_t seed, const std::string& name) {
  return Vec3(drawError(sigma.x(), seed, name + ".x"), drawError(sigma.y(), seed, name + ".y"),
              drawError(sigma.z(), seed, name + ".z"));
}

CalibrationErrors drawCalibrationErrors(const CalibrationErrors& sigma, uint64_t seed) {
  CalibrationErrors e;
  e.draw = true;
  e.lidar = drawExtrinsic(sigma.lidar, seed, "lidar");
  e.camera = drawExtrinsic(sigma.camera, seed, "camera");
  e.wheel = drawExtrinsic(sigma.wheel, seed, "wheel");
  e.lidar_time_offset_s = drawError(sigma.lidar_time_offset_s, seed, "lidar_time_offset_s");
  e.camera_time_offset_s = drawError(sigma.camera_time_offset_s, seed, "camera_time_offset_s");
  e.wheel_time_offset_s = drawError(sigma.wheel_time_offset_s, seed, "wheel_time_offset_s");
  return e;
}

}  // namespace livo::sim
