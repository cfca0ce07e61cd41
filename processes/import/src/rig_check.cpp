#include "livo/import/rig_check.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "livo/import/import_report.hpp"
#include "livo/import/lidar_models.hpp"

namespace livo::import {

namespace {

std::string fmt(double v, int precision = 6) {
  std::ostringstream os;
  os.precision(precision);
  os << v;
  return os.str();
}

std::string size(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

class Findings {
 public:
  explicit Findings(std::string rig_file) : rig_(std::move(rig_file)) {}
  void error(const std::string& m) { out_.push_back({true, m}); }
  void warning(const std::string& m) { out_.push_back({false, m}); }
  /// "the rig (FILE: rig.KEY) says X, the log Y"
  std::string says(const std::string& key, const std::string& rig_value, const std::string& log_value) const {
    return "the rig (" + rig_ + ": rig." + key + ") says " + rig_value + ", " + log_value;
  }
  void rate(const std::string& sensor, const std::string& key, double rig_hz, const MeasuredRate& r) {
    if (r.hz > 0 && std::abs(r.hz - rig_hz) > 0.05 * rig_hz)
      warning(sensor + " rate: " + says(key, fmt(rig_hz) + " Hz", "the log's stamps " + fmt(r.hz, 4) + " Hz"));
  }
  std::vector<RigFinding> sorted() {
    std::stable_sort(out_.begin(), out_.end(),
                     [](const RigFinding& a, const RigFinding& b) { return a.error && !b.error; });
    return out_;
  }

 private:
  std::string rig_;
  std::vector<RigFinding> out_;
};

void checkChannel(Findings& f, const char* sensor, const std::string& rig_channel, const std::string& written) {
  if (rig_channel != written)
    f.error(std::string(sensor) +
            " channel: " + f.says(std::string("channels.") + sensor, rig_channel, "the log has it on " + written));
}

void checkImu(Findings& f, const SensorRig& rig, const SensorSurvey& s) {
  if (!s.imu) {
    f.error(
        "IMU: the log has none, and every estimator needs one (pick the topic with --imu; --list-topics shows them)");
    return;
  }
  f.rate("IMU", "imu.rate_hz", rig.imu.rate_hz, s.imu->rate);
  if (s.imu->first_second_samples > 10 && s.imu->first_second_accel_std < 0.05 &&
      std::abs(s.imu->first_second_accel_norm - rig.imu.gravity) > 0.3)
    f.warning("gravity: " + f.says("imu.gravity", fmt(rig.imu.gravity) + " m/s^2",
                                   "the accelerometer reads " + fmt(s.imu->first_second_accel_norm, 4) +
                                       " m/s^2 at rest over the log's first second (units? a large bias?)"));
}

void checkLidar(Findings& f, const SensorRig& rig, const SensorSurvey& s) {
  if (rig.lidar && !s.lidar) {
    f.error("LiDAR: the rig has one (livo-lio needs it) but the log has no sweeps (pick the topic with --lidar)");
    return;
  }
  if (!rig.lidar) {
    if (s.lidar) f.warning("LiDAR: the log has sweeps but the rig has no lidar: section; they are not used");
    return;
  }
  const LidarSurvey& l = *s.lidar;
  f.rate("LiDAR", "lidar.rate_hz", rig.lidar->rate_hz, l.rate);
  if (const LidarModelFacts* m = findLidarModel(rig.lidar->model)) {
    if (m->rings != l.rings)
      f.warning("LiDAR rings: " + f.says("lidar.model",
                                         rig.lidar->model + " (" + std::to_string(m->rings) + " " +
                                             (m->solid_state ? "scan lines" : "rings") + ")",
                                         "the log's sweeps have " + std::to_string(l.rings)));
    if (m->solid_state != l.solid_state)
      f.warning("LiDAR pattern: " +
                f.says("lidar.model", rig.lidar->model + (m->solid_state ? " (solid-state)" : " (spinning)"),
                       std::string("the log's sweeps are ") + (l.solid_state ? "solid-state" : "spinning")));
  }
}

void checkIntrinsics(Findings& f, const CameraRig& c, const CameraIntrinsics& k, const CameraSurvey& img) {
  if (k.width > 0 && (k.width != img.width || k.height != img.height))
    f.warning("camera calibration size: " + k.source + " is for " + size(k.width, k.height) +
              ", the images in the log are " + size(img.width, img.height) +
              " (binned or cropped images: the intrinsics need scaling)");
  const std::pair<const char*, std::pair<double, double>> values[] = {
      {"fx", {c.fx, k.fx}}, {"fy", {c.fy, k.fy}}, {"cx", {c.cx, k.cx}}, {"cy", {c.cy, k.cy}}};
  std::string differ_rig, differ_log;
  for (const auto& [key, v] : values) {
    if (std::abs(v.first - v.second) > std::max(0.5, 0.002 * std::abs(v.second))) {
      differ_rig += std::string(differ_rig.empty() ? "" : ", ") + key + " " + fmt(v.first);
      differ_log += std::string(differ_log.empty() ? "" : ", ") + key + " " + fmt(v.second);
    }
  }
  if (!differ_rig.empty())
    f.warning("camera intrinsics: " + f.says("camera", differ_rig, k.source + " says " + differ_log));
  if (c.distortion_model != k.distortion_model) {
    f.warning("camera distortion model: " + f.says("camera.distortion_model", distortionModelName(c.distortion_model),
                                                   k.source + " says " + distortionModelName(k.distortion_model)));
  } else {
    bool differ = false;
    for (int i = 0; i < 4; ++i) differ = differ || std::abs(c.distortion[i] - k.distortion[i]) > 1e-3;
    if (differ)
      f.warning("camera distortion: " +
                f.says("camera.distortion", yamlList(std::vector<double>(c.distortion.begin(), c.distortion.end())),
                       k.source + " says " + yamlList(std::vector<double>(k.distortion.begin(), k.distortion.end()))));
  }
}

void checkCamera(Findings& f, const SensorRig& rig, const SensorSurvey& s, const InputCalibration& cal) {
  if (rig.camera && !s.camera) {
    f.warning(
        "camera: the rig has one but the log has no images: livo-vio and livo-colour get nothing (pick the topic "
        "with --camera)");
    return;
  }
  if (!rig.camera) {
    if (s.camera) f.warning("camera: the log has images but the rig has no camera: section; they are not used");
    return;
  }
  const CameraRig& c = *rig.camera;
  const CameraSurvey& img = *s.camera;
  if (c.width != img.width || c.height != img.height)
    f.error("camera image size: " + f.says("camera.width/height", size(c.width, c.height),
                                           "the images in the log are " + size(img.width, img.height)));
  if (img.other_sizes)
    f.warning("camera image size: " + std::to_string(img.other_sizes) + " images in the log differ from the first's " +
              size(img.width, img.height));
  if (cal.camera) checkIntrinsics(f, c, *cal.camera, img);
  f.rate("camera", "camera.rate_hz", c.rate_hz, img.rate);
  if (img.channels && c.color != (img.channels >= 3))
    f.warning("camera colour: " + f.says("camera.color", c.color ? "true (colour)" : "false (grey)",
                                         "the images are " + std::string(img.channels >= 3 ? "colour" : "grey") + " (" +
                                             img.encoding + ")"));
}

}  // namespace

std::vector<RigFinding> checkRigAgainstLog(const SensorRig& rig, const std::string& rig_file,
                                           const SensorSurvey& survey, const InputCalibration& calibration,
                                           const ChannelNames& written) {
  Findings f(rig_file);
  if (survey.imu) checkChannel(f, "imu", rig.channels.imu, written.imu);
  if (survey.lidar && rig.lidar) checkChannel(f, "lidar", rig.channels.lidar, written.lidar);
  if (survey.camera && rig.camera) checkChannel(f, "camera", rig.channels.camera, written.camera);
  if (survey.ground_truth_poses) checkChannel(f, "ground_truth", rig.channels.ground_truth, written.ground_truth);
  checkImu(f, rig, survey);
  checkLidar(f, rig, survey);
  checkCamera(f, rig, survey, calibration);
  return f.sorted();
}

}  // namespace livo::import
