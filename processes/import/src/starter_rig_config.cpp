#include "livo/import/starter_rig_config.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "livo/import/import_report.hpp"
#include "livo/import/lidar_models.hpp"

namespace livo::import {

namespace {

constexpr size_t kCommentColumn = 36;  // as the config/rigs/ templates align their comments

/// Lines of YAML with a comment aligned at kCommentColumn.
class YamlText {
 public:
  void comment(const std::string& text) { out_ << "# " << text << "\n"; }
  void raw(const std::string& text) { out_ << text << "\n"; }
  void line(int indent, const std::string& key, const std::string& value, const std::string& comment = "") {
    std::string text(static_cast<size_t>(indent), ' ');
    text += key + ":" + (value.empty() ? "" : " " + value);
    if (!comment.empty()) {
      text.resize(std::max(text.size() + 1, kCommentColumn), ' ');
      text += "# " + comment;
    }
    out_ << text << "\n";
  }
  std::string str() const { return out_.str(); }

 private:
  std::ostringstream out_;
};

/// A measured rate as written: whole hertz when within 0.5 % of one, else two decimals.
double roundedRate(double hz) {
  const double whole = std::round(hz);
  if (whole > 0 && std::abs(hz - whole) <= 0.005 * whole) return whole;
  return std::round(hz * 100.0) / 100.0;
}

std::string measuredRateComment(const MeasuredRate& r, const char* what) {
  return "measured: 1 / the median interval of " + std::to_string(r.messages) + " " + what + " stamps";
}

std::string num(double v) { return yamlNumber(v); }

void writeHeader(YamlText& y, const StarterRigInputs& in) {
  y.comment("Starter rig written by livo-import --rig-out from the " + in.format + " input " + in.input);
  y.comment("(log " + in.log + "). What the input told is filled in and says where it came from;");
  y.comment("every value it could not tell is marked \"REPLACE:\" with the placeholder used. The file");
  y.comment("runs as it is (each placeholder is a valid value), but the estimate is only as good as");
  y.comment("the numbers: replace them (config/rigs/README.md, \"Adapting a template\"), check it with");
  y.comment("  for p in lio vio loop colour octomap; do build/bin/livo-$p --config THIS_FILE --check-config; done");
  y.comment("and run the log with");
  y.comment("  scripts/run_pipeline.sh --log " + in.log + " --config THIS_FILE --out runs/NAME");
  if (!in.calibration.calibrated_rig.empty())
    y.comment(in.calibration.calibrated_rig + " is this dataset's calibrated rig: prefer it to this starter.");
  std::string counts;
  for (const auto& [channel, n] : in.channel_counts)
    counts += (counts.empty() ? "" : ", ") + channel + " " + std::to_string(n);
  y.comment("Messages in the log: " + (counts.empty() ? std::string("none") : counts));
}

void writeChannels(YamlText& y, const StarterRigInputs& in) {
  const SensorSurvey& s = in.survey;
  std::string channels = "{imu: " + in.channels.imu;
  if (s.lidar) channels += ", lidar: " + in.channels.lidar;
  if (s.camera) channels += ", camera: " + in.channels.camera;
  if (s.camera && s.depth_images) channels += ", depth: " + in.channels.depth;
  channels += ", ground_truth: " + in.channels.ground_truth + "}";
  y.line(2, "channels", channels, "the channels livo-import wrote");
}

void writeImu(YamlText& y, const StarterRigInputs& in) {
  const std::optional<ImuSurvey>& imu = in.survey.imu;
  const std::optional<ImuNoise>& noise = in.calibration.imu_noise;
  y.line(2, "imu", "",
         imu ? "the body frame is the IMU's" : "REPLACE: the log has no IMU; livo-lio needs one (placeholders below)");
  if (imu && imu->rate.hz > 0)
    y.line(4, "rate_hz", num(roundedRate(imu->rate.hz)), measuredRateComment(imu->rate, "IMU"));
  else
    y.line(4, "rate_hz", "200", "REPLACE: the IMU's rate, Hz (placeholder: 200; not measured)");
  if (noise) {
    y.raw("    # " + noise->source + "'s white noise is the sensor's at rest: where motors shake the IMU (a drone's");
    y.raw(
        "    # rotors, an engine), state what it reads with them running (processes/lio/README.md, \"The IMU's noise "
        "on a drone\")");
    y.line(4, "gyro_noise_density", num(noise->gyro_noise_density), noise->source + ": rad/s/sqrt(Hz)");
    y.line(4, "gyro_random_walk", num(noise->gyro_random_walk), noise->source + ": rad/s^2/sqrt(Hz)");
    y.line(4, "accel_noise_density", num(noise->accel_noise_density), noise->source + ": m/s^2/sqrt(Hz)");
    y.line(4, "accel_random_walk", num(noise->accel_random_walk), noise->source + ": m/s^3/sqrt(Hz)");
  } else {
    y.line(4, "gyro_noise_density", "2.4e-4",
           "REPLACE: rad/s/sqrt(Hz), datasheet or Allan variance (placeholder: a BMI088-class MEMS, 0.014 "
           "deg/s/sqrt(Hz))");
    y.line(4, "gyro_random_walk", "2.0e-5",
           "REPLACE: rad/s^2/sqrt(Hz), Allan variance (placeholder: a consumer MEMS gyro)");
    y.line(4, "accel_noise_density", "1.7e-3",
           "REPLACE: m/s^2/sqrt(Hz) (placeholder: a BMI088-class MEMS, 175 ug/sqrt(Hz))");
    y.line(4, "accel_random_walk", "1.0e-3",
           "REPLACE: m/s^3/sqrt(Hz), Allan variance (placeholder: a consumer MEMS accelerometer)");
  }
  std::string gravity = "REPLACE: local gravity, m/s^2 (placeholder: 9.81; 9.78 at the equator, 9.83 at the poles)";
  if (imu && imu->first_second_samples > 1) {
    std::ostringstream os;
    os.precision(4);
    os << std::fixed << "; the log's first second reads |accel| " << imu->first_second_accel_norm << " +- "
       << imu->first_second_accel_std
       << (imu->first_second_accel_std < 0.05 ? " (at rest: gravity + bias)" : " (moving)");
    gravity += os.str();
  }
  y.line(4, "gravity", "9.81", gravity);
}

void writeLidar(YamlText& y, const StarterRigInputs& in) {
  const LidarSurvey& l = *in.survey.lidar;
  const LidarModelGuess guess = guessLidarModel(l.rings, l.solid_state, in.lidar_layout, in.calibration.lidar_model);
  const LidarModelFacts& f = *guess.facts;
  if (!in.lidar_layout.empty()) y.raw("  # point layout in the input: " + in.lidar_layout);
  y.line(2, "lidar", "",
         l.point_times ? "" : "the sweeps carry no per-point times: motion within a sweep is not undone");
  std::string model_comment = guess.reason == "named by the input"
                                  ? "named by the input (" + in.calibration.lidar_model_source + ")"
                                  : "guessed from the log: " + guess.reason;
  if (!guess.exact)
    model_comment = "REPLACE: " + model_comment;
  else
    model_comment += " (a label: the estimators use the rate, ranges, noise and T_I_L)";
  y.line(4, "model", f.model, model_comment);
  if (l.rate.hz > 0) {
    std::ostringstream sweep;
    sweep << "; sweeps span " << yamlNumber(std::round(l.sweep_duration_s * 1e4) / 1e4) << " s, median "
          << l.median_points << " points";
    y.line(4, "rate_hz", num(roundedRate(l.rate.hz)), measuredRateComment(l.rate, "sweep") + sweep.str());
  } else {
    y.line(4, "rate_hz", "10", "REPLACE: the sweep rate, Hz (placeholder: 10; a single sweep in the log)");
  }
  y.line(4, "min_range", l.solid_state ? "1.0" : "0.5",
         std::string("REPLACE: m, larger if the sensor sees your vehicle (placeholder: ") +
             (l.solid_state ? "1.0" : "0.5") + ", near returns off the mount)");
  const std::string of_model = guess.reason == "named by the input" ? "" : " (the guessed model's)";
  y.line(4, "max_range", num(f.max_range), f.source + of_model + (guess.exact ? "" : "; REPLACE: with your model's"));
  y.line(4, "range_noise_std", num(f.range_noise_std),
         f.source + of_model + (guess.exact ? "" : "; REPLACE: with your model's"));
  if (const std::optional<KnownExtrinsic>& T = in.calibration.T_I_L)
    y.line(4, "T_I_L", T->yaml.empty() ? extrinsicYaml(T->T) : T->yaml, "p_I = T_I_L p_L: " + T->source);
  else
    y.line(4, "T_I_L", "{translation: [0.0, 0.0, 0.0], rpy_deg: [0, 0, 0]}",
           "REPLACE: p_I = T_I_L p_L, from CAD or a LiDAR-IMU calibration (placeholder: identity, the LiDAR at the "
           "IMU, axes aligned)");
}

void writeCamera(YamlText& y, const StarterRigInputs& in) {
  const CameraSurvey& c = *in.survey.camera;
  const std::optional<CameraIntrinsics>& k = in.calibration.camera;
  y.line(2, "camera", "",
         k ? "calibration from " + k->source : "REPLACE: the input held no calibration of this camera");
  const std::string images = std::to_string(c.rate.messages) + " " + c.encoding + " images";
  std::string size_note;
  if (c.other_sizes) size_note = "; " + std::to_string(c.other_sizes) + " images have another size";
  if (k && k->width > 0 && (k->width != c.width || k->height != c.height))
    size_note += "; REPLACE: " + k->source + " is for " + std::to_string(k->width) + "x" + std::to_string(k->height) +
                 ": scale the intrinsics to the images";
  y.line(4, "width", std::to_string(c.width), "measured: the first of " + images + size_note);
  y.line(4, "height", std::to_string(c.height), "measured: the first of " + images);
  if (k) {
    const bool ros = k->source.rfind("camera_info", 0) == 0;  // K of a CameraInfo, else an ASL fu fv cu cv
    y.line(4, "fx", num(k->fx), k->source + (ros ? ": K[0]" : ": fu"));
    y.line(4, "fy", num(k->fy), k->source + (ros ? ": K[4]" : ": fv"));
    y.line(4, "cx", num(k->cx), k->source + (ros ? ": K[2]" : ": cu"));
    y.line(4, "cy", num(k->cy), k->source + (ros ? ": K[5]" : ": cv"));
    y.line(4, "distortion_model", distortionModelName(k->distortion_model), k->source);
    y.line(4, "distortion", yamlList(std::vector<double>(k->distortion.begin(), k->distortion.end())),
           k->source + (k->distortion_model == DistortionModel::kRadtan ? ": k1 k2 p1 p2" : ": k1 k2 k3 k4") +
               (k->note.empty() ? "" : "; REPLACE: " + k->note));
  } else {
    const double f = c.width / 2.0;
    y.line(4, "fx", num(f), "REPLACE: focal length x, px (placeholder: width / 2, a 90 deg horizontal field)");
    y.line(4, "fy", num(f), "REPLACE: focal length y, px (placeholder: fx)");
    y.line(4, "cx", num((c.width - 1) / 2.0), "REPLACE: principal point x, px (placeholder: the image centre)");
    y.line(4, "cy", num((c.height - 1) / 2.0), "REPLACE: principal point y, px (placeholder: the image centre)");
    y.line(4, "distortion_model", "radtan", "REPLACE: radtan (k1 k2 p1 p2) or equidistant (fisheye, k1..k4)");
    y.line(4, "distortion", "[0.0, 0.0, 0.0, 0.0]", "REPLACE: the four coefficients of that model (placeholder: none)");
  }
  if (c.rate.hz > 0)
    y.line(4, "rate_hz", num(roundedRate(c.rate.hz)), measuredRateComment(c.rate, "image"));
  else
    y.line(4, "rate_hz", "20", "REPLACE: frame rate, Hz (placeholder: 20; one image in the log)");
  if (c.channels)
    y.line(4, "color", c.channels >= 3 ? "true" : "false",
           "measured: the images are " + std::string(c.channels >= 3 ? "colour" : "grey") + " (" + c.encoding + ")");
  else
    y.line(4, "color", "true",
           "REPLACE: true for a colour camera, false for grey (the " + c.encoding + " header was cut short)");
  if (in.survey.depth_images)
    y.line(4, "depth", "true",
           "measured: " + std::to_string(in.survey.depth_images) + " depth images registered to it on " +
               in.channels.depth);
  y.line(4, "time_offset_s", "0.0",
         "REPLACE: image stamp + offset = the same instant on the IMU clock (Kalibr's timeshift_cam_imu), 0 if "
         "triggered or unknown");
  if (const std::optional<KnownExtrinsic>& T = in.calibration.T_I_C) {
    y.line(4, "T_I_C", T->yaml.empty() ? extrinsicYaml(T->T) : T->yaml, "p_I = T_I_C p_C: " + T->source);
  } else {
    y.raw("    # REPLACE: p_I = T_I_C p_C, camera frame z forward, x right, y down (Kalibr's T_cam_imu inverted).");
    y.raw("    # Placeholder: looking forward along the body's x with the camera at the body origin.");
    y.line(4, "T_I_C", "{translation: [0.0, 0.0, 0.0], rpy_deg: [-90, 0, -90]}");
  }
}

void writePipeline(YamlText& y, const StarterRigInputs& in) {
  const bool lidar = in.survey.lidar.has_value(), camera = in.survey.camera.has_value();
  y.raw("");
  y.comment("Pipeline processes (scripts/run_pipeline.sh runs those with a section here); every key is");
  y.comment("optional, the defaults are in each process's README. Tune after a first run (report.md).");
  if (lidar) {
    if (camera) {
      y.raw("lio:");
      y.line(2, "camera_handoff", "true", "STATE_PRIOR at image times for livo-vio (LiDAR-only while no VIO runs)");
      y.raw("vio: {}");
    } else {
      y.line(0, "lio", "{}", "no camera in the log: LiDAR-inertial only (no vio:, colour:)");
    }
    y.raw("loop:");
    y.line(2, "output_dir", ".",
           "run_pipeline.sh runs processes in DIR: loops.json, keyframes.tum, global_map.ply land there");
    if (camera) y.raw("colour: {}");
    y.raw("octomap: {}");
  } else if (camera) {
    y.comment("No LiDAR in the log: livo-lio, livo-loop and livo-octomap have nothing to work on;");
    y.comment("livo-vio-feature (KLT + IMU sliding window) runs on the camera and the IMU alone.");
    y.raw("vio_feature: {}");
  } else {
    y.comment("No LiDAR and no camera in the log: no pipeline process can run on it.");
  }
}

}  // namespace

std::string starterRigConfig(const StarterRigInputs& in) {
  YamlText y;
  writeHeader(y, in);
  y.raw("rig:");
  writeChannels(y, in);
  writeImu(y, in);
  if (in.survey.lidar) writeLidar(y, in);
  if (in.survey.camera) writeCamera(y, in);
  writePipeline(y, in);
  return y.str();
}

void writeStarterRigConfig(const std::string& path, const StarterRigInputs& in) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write the starter rig");
  out << starterRigConfig(in);
  if (!out) throw std::runtime_error(path + ": write failed");
}

}  // namespace livo::import
