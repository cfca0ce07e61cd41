#include "livo/sensor_rig.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <ostream>

namespace livo {

const std::vector<std::string> kLidarModels = {"VLP-16",  "OS1-16",  "OS1-64",  "HDL-64E",      "livox-avia", "VLP-32C",
                                               "OS0-128", "OS1-128", "OS2-128", "livox-mid360", "hesai-xt32"};

const char* distortionModelName(DistortionModel m) {
  return m == DistortionModel::kEquidistant ? "equidistant" : "radtan";
}

namespace {

void requirePositive(const Config& c, const std::string& key, double v) {
  if (!(v > 0.0)) throw ConfigError(c.where(key) + ": must be > 0 (got " + std::to_string(v) + ")");
}
void requireNonNegative(const Config& c, const std::string& key, double v) {
  if (!(v >= 0.0)) throw ConfigError(c.where(key) + ": must be >= 0 (got " + std::to_string(v) + ")");
}

ImuRig readImu(const Config& c) {
  ImuRig imu;
  c.read("rate_hz", imu.rate_hz);
  c.read("gyro_noise_density", imu.gyro_noise_density);
  c.read("gyro_random_walk", imu.gyro_random_walk);
  c.read("accel_noise_density", imu.accel_noise_density);
  c.read("accel_random_walk", imu.accel_random_walk);
  c.readOptional("gyro_scale_std", imu.gyro_scale_std);
  c.readOptional("gyro_misalignment_std", imu.gyro_misalignment_std);
  c.readOptional("accel_scale_std", imu.accel_scale_std);
  c.readOptional("accel_misalignment_std", imu.accel_misalignment_std);
  c.readOptional("gravity", imu.gravity);
  requirePositive(c, "rate_hz", imu.rate_hz);
  requireNonNegative(c, "gyro_noise_density", imu.gyro_noise_density);
  requireNonNegative(c, "gyro_random_walk", imu.gyro_random_walk);
  requireNonNegative(c, "accel_noise_density", imu.accel_noise_density);
  requireNonNegative(c, "accel_random_walk", imu.accel_random_walk);
  requireNonNegative(c, "gyro_scale_std", imu.gyro_scale_std);
  requireNonNegative(c, "gyro_misalignment_std", imu.gyro_misalignment_std);
  requireNonNegative(c, "accel_scale_std", imu.accel_scale_std);
  requireNonNegative(c, "accel_misalignment_std", imu.accel_misalignment_std);
  requirePositive(c, "gravity", imu.gravity);
  return imu;
}

CalibrationUncertainty readCalibrationUncertainty(const Config& sensor) {
  CalibrationUncertainty u;
  if (!sensor.has("calibration_std")) return u;
  const Config c = sensor.section("calibration_std");
  c.readOptional("rotation_deg", u.rotation_deg);
  c.readOptional("translation", u.translation);
  c.readOptional("time_offset_s", u.time_offset_s);
  c.checkAllUsed();
  if (!(u.rotation_deg >= 0.0 && u.rotation_deg <= 10.0))
    throw ConfigError(c.where("rotation_deg") + ": must be in [0, 10] deg");
  if (!(u.translation >= 0.0 && u.translation <= 1.0))
    throw ConfigError(c.where("translation") + ": must be in [0, 1] m");
  if (!(u.time_offset_s >= 0.0 && u.time_offset_s <= 0.1))
    throw ConfigError(c.where("time_offset_s") + ": must be in [0, 0.1] s");
  return u;
}

void printCalibrationUncertainty(std::ostream& os, const CalibrationUncertainty& u) {
  if (!u.any()) return;
  os << ", known to " << u.rotation_deg << " deg / " << u.translation << " m / " << u.time_offset_s * 1e3 << " ms";
}

LidarRig readLidar(const Config& c) {
  LidarRig l;
  c.read("model", l.model);
  if (std::find(kLidarModels.begin(), kLidarModels.end(), l.model) == kLidarModels.end()) {
    std::string list;
    for (const auto& m : kLidarModels) list += (list.empty() ? "" : ", ") + m;
    throw ConfigError(c.where("model") + ": unknown LiDAR model '" + l.model + "' (known: " + list + ")");
  }
  c.read("rate_hz", l.rate_hz);
  c.read("min_range", l.min_range);
  c.read("max_range", l.max_range);
  c.read("range_noise_std", l.range_noise_std);
  c.readOptional("dropout_probability", l.dropout_probability);
  c.read("T_I_L", l.T_I_L);
  l.calibration_std = readCalibrationUncertainty(c);
  requirePositive(c, "rate_hz", l.rate_hz);
  requireNonNegative(c, "min_range", l.min_range);
  if (!(l.max_range > l.min_range)) throw ConfigError(c.where("max_range") + ": must be greater than min_range");
  requireNonNegative(c, "range_noise_std", l.range_noise_std);
  if (!(l.dropout_probability >= 0.0 && l.dropout_probability < 1.0))
    throw ConfigError(c.where("dropout_probability") + ": must be in [0, 1)");
  return l;
}

CameraRig readCamera(const Config& c) {
  CameraRig cam;
  c.read("width", cam.width);
  c.read("height", cam.height);
  c.read("fx", cam.fx);
  c.read("fy", cam.fy);
  c.read("cx", cam.cx);
  c.read("cy", cam.cy);
  std::string model = distortionModelName(cam.distortion_model);
  c.readOptional("distortion_model", model);
  if (model == distortionModelName(DistortionModel::kRadtan))
    cam.distortion_model = DistortionModel::kRadtan;
  else if (model == distortionModelName(DistortionModel::kEquidistant))
    cam.distortion_model = DistortionModel::kEquidistant;
  else
    throw ConfigError(c.where("distortion_model") + ": '" + model + "' is not radtan or equidistant");
  std::vector<double> d;
  if (c.readOptional("distortion", d)) {
    if (d.size() != 4)
      throw ConfigError(c.where("distortion") + (cam.distortion_model == DistortionModel::kRadtan
                                                     ? ": expected [k1, k2, p1, p2] (radtan)"
                                                     : ": expected [k1, k2, k3, k4] (equidistant)"));
    std::copy(d.begin(), d.end(), cam.distortion.begin());
  }
  c.read("rate_hz", cam.rate_hz);
  c.readOptional("color", cam.color);
  c.readOptional("depth", cam.depth);
  c.read("T_I_C", cam.T_I_C);
  c.readOptional("time_offset_s", cam.time_offset_s);
  if (!(std::abs(cam.time_offset_s) < 1.0)) throw ConfigError(c.where("time_offset_s") + ": must be within (-1, 1) s");
  c.readOptional("rolling_shutter_s", cam.rolling_shutter_s);
  cam.calibration_std = readCalibrationUncertainty(c);
  if (cam.width <= 0 || cam.width > 10000) throw ConfigError(c.where("width") + ": must be in 1..10000");
  if (cam.height <= 0 || cam.height > 10000) throw ConfigError(c.where("height") + ": must be in 1..10000");
  requirePositive(c, "fx", cam.fx);
  requirePositive(c, "fy", cam.fy);
  requirePositive(c, "rate_hz", cam.rate_hz);
  if (!(cam.rolling_shutter_s >= 0.0 && cam.rolling_shutter_s <= 1.0 / cam.rate_hz))
    throw ConfigError(c.where("rolling_shutter_s") + ": must be within [0, 1 / rate_hz] s");
  return cam;
}

WheelRig readWheel(const Config& c) {
  WheelRig w;
  c.read("rate_hz", w.rate_hz);
  c.read("track_width", w.track_width);
  c.read("speed_noise_std", w.speed_noise_std);
  c.read("T_I_B", w.T_I_B);
  w.calibration_std = readCalibrationUncertainty(c);
  // the graphs estimate the wheel frame's rotation only: a stated translation or time offset would
  // be a belief nothing acts on
  if (w.calibration_std.translation > 0.0 || w.calibration_std.time_offset_s > 0.0)
    throw ConfigError(c.where("calibration_std") +
                      ": of the wheel only rotation_deg is estimated (translation and time_offset_s must be 0)");
  requirePositive(c, "rate_hz", w.rate_hz);
  requirePositive(c, "track_width", w.track_width);
  requireNonNegative(c, "speed_noise_std", w.speed_noise_std);
  return w;
}

void printPose(std::ostream& os, const Pose3& T) {
  const Vec3 t = T.translation();
  // R = Rz(yaw) Ry(pitch) Rx(roll), as rpy_deg in a config
  const Mat3 R = T.linear();
  const double k = 180.0 / M_PI;
  const double roll = std::atan2(R(2, 1), R(2, 2)) * k, pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0)) * k,
               yaw = std::atan2(R(1, 0), R(0, 0)) * k;
  os << "translation [" << t.x() << ", " << t.y() << ", " << t.z() << "], rpy_deg [" << roll << ", " << pitch << ", "
     << yaw << "]";
}

}  // namespace

SensorRig readSensorRig(const Config& rig) {
  SensorRig r;
  const Config ch = rig.optionalSection("channels");
  ch.readOptional("imu", r.channels.imu);
  ch.readOptional("lidar", r.channels.lidar);
  ch.readOptional("camera", r.channels.camera);
  ch.readOptional("depth", r.channels.depth);
  ch.readOptional("wheel", r.channels.wheel);
  ch.readOptional("ground_truth", r.channels.ground_truth);
  r.imu = readImu(rig.section("imu"));
  if (rig.has("lidar")) r.lidar = readLidar(rig.section("lidar"));
  if (rig.has("camera")) r.camera = readCamera(rig.section("camera"));
  if (rig.has("wheel")) r.wheel = readWheel(rig.section("wheel"));
  rig.checkAllUsed();
  if (r.camera && r.camera->depth && r.channels.depth == r.channels.camera)
    throw ConfigError(ch.where("depth") + ": the depth images need a channel of their own, not the camera's (" +
                      r.channels.camera + ")");
  return r;
}

void printSensorRig(const SensorRig& r, std::ostream& os) {
  os << "rig:\n";
  os << "  imu:    " << r.imu.rate_hz << " Hz on " << r.channels.imu << ", gyro " << r.imu.gyro_noise_density
     << " rad/s/sqrt(Hz) (walk " << r.imu.gyro_random_walk << "), accel " << r.imu.accel_noise_density
     << " m/s^2/sqrt(Hz) (walk " << r.imu.accel_random_walk << "), gravity " << r.imu.gravity << "\n";
  if (r.lidar) {
    const auto& l = *r.lidar;
    os << "  lidar:  " << l.model << " at " << l.rate_hz << " Hz on " << r.channels.lidar << ", range " << l.min_range
       << ".." << l.max_range << " m, noise " << l.range_noise_std << " m, dropout " << l.dropout_probability
       << "\n          T_I_L ";
    printPose(os, l.T_I_L);
    printCalibrationUncertainty(os, l.calibration_std);
    os << "\n";
  }
  if (r.camera) {
    const auto& c = *r.camera;
    os << "  camera: " << c.width << "x" << c.height << (c.color ? " RGB8" : " GRAY8") << " at " << c.rate_hz
       << " Hz on " << r.channels.camera << ", f " << c.fx << "/" << c.fy << ", c " << c.cx << "/" << c.cy << ", "
       << distortionModelName(c.distortion_model) << " distortion [" << c.distortion[0] << ", " << c.distortion[1]
       << ", " << c.distortion[2] << ", " << c.distortion[3] << "]";
    if (c.depth) os << "\n          depth images registered to it on " << r.channels.depth;
    os << "\n          T_I_C ";
    printPose(os, c.T_I_C);
    printCalibrationUncertainty(os, c.calibration_std);
    os << "\n";
  }
  if (r.wheel) {
    const auto& w = *r.wheel;
    os << "  wheel:  " << w.rate_hz << " Hz on " << r.channels.wheel << ", track " << w.track_width << " m, noise "
       << w.speed_noise_std << " m/s\n          T_I_B ";
    printPose(os, w.T_I_B);
    if (w.calibration_std.rotation_deg > 0.0) os << ", rotation known to " << w.calibration_std.rotation_deg << " deg";
    os << "\n";
  }
  os << "  ground truth on " << r.channels.ground_truth << "\n";
}

}  // namespace livo
