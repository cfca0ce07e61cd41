#include "livo/sim/simulation_setup.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <ostream>
#include <sstream>

#include "livo/sim/car_trajectory.hpp"
#include "livo/sim/lidar_pattern.hpp"
#include "livo/sim/scene_config.hpp"
#include "livo/sim/trajectory_config.hpp"

namespace livo::sim {

namespace {

std::string dirOf(const std::string& file) {
  const size_t slash = file.rfind('/');
  return slash == std::string::npos ? "." : file.substr(0, slash);
}

std::string resolve(const std::string& base_dir, const std::string& path) {
  if (path.empty() || path[0] == '/' || base_dir.empty()) return path;
  return base_dir + "/" + path;
}

/// The rig may name real LiDARs (config/rigs/) that have no beam table here.
void requireSimulatedLidar(const Config& lidar, const std::string& model) {
  const std::vector<std::string>& simulated = LidarPattern::models();
  if (std::find(simulated.begin(), simulated.end(), model) != simulated.end()) return;
  std::string list;
  for (const std::string& m : simulated) list += (list.empty() ? "" : ", ") + m;
  throw ConfigError(lidar.where("model") + ": livo-sim cannot simulate a '" + model + "' (it simulates " + list + ")");
}

std::string number(double x) {
  std::ostringstream os;
  os << x;
  return os.str();
}

/// A scalar error within +-limit; a 1-sigma (draw) must also be >= 0.
void readErrorWithin(const Config& c, const std::string& key, double limit, bool sigma, double* v) {
  if (!c.readOptional(key, *v)) return;
  if (!(std::abs(*v) <= limit)) throw ConfigError(c.where(key) + ": must be within +-" + number(limit));
  if (sigma && *v < 0.0) throw ConfigError(c.where(key) + ": a 1-sigma (calibration_errors.draw) must be >= 0");
}

/// A 3-vector error, every component as readErrorWithin.
void readErrorWithin(const Config& c, const std::string& key, double limit, bool sigma, Vec3* v) {
  if (!c.readOptional(key, *v)) return;
  for (int i = 0; i < 3; ++i) {
    if (!(std::abs((*v)[i]) <= limit))
      throw ConfigError(c.where(key) + ": components must be within +-" + number(limit));
    if (sigma && (*v)[i] < 0.0) throw ConfigError(c.where(key) + ": a 1-sigma (calibration_errors.draw) must be >= 0");
  }
}

void requireSensor(const Config& c, const std::string& key, bool present, const std::string& sensor) {
  if (c.has(key) && !present) throw ConfigError(c.where(key) + ": the rig has no " + sensor);
}

void readExtrinsicError(const Config& parent, const std::string& key, bool sigma, ExtrinsicError* e) {
  const Config c = parent.optionalSection(key);
  readErrorWithin(c, "translation", 1.0, sigma, &e->translation);
  readErrorWithin(c, "rpy_deg", 10.0, sigma, &e->rpy_deg);
  c.checkAllUsed();
}

void readCalibrationErrors(const Config& c, const SensorRig& rig, CalibrationErrors* e) {
  c.readOptional("draw", e->draw);
  requireSensor(c, "lidar", rig.lidar.has_value(), "lidar");
  requireSensor(c, "lidar_time_offset_s", rig.lidar.has_value(), "lidar");
  requireSensor(c, "camera", rig.camera.has_value(), "camera");
  requireSensor(c, "camera_time_offset_s", rig.camera.has_value(), "camera");
  requireSensor(c, "wheel", rig.wheel.has_value(), "wheel encoder");
  requireSensor(c, "wheel_time_offset_s", rig.wheel.has_value(), "wheel encoder");
  readExtrinsicError(c, "lidar", e->draw, &e->lidar);
  readExtrinsicError(c, "camera", e->draw, &e->camera);
  readExtrinsicError(c, "wheel", e->draw, &e->wheel);
  readErrorWithin(c, "lidar_time_offset_s", 0.5, e->draw, &e->lidar_time_offset_s);
  readErrorWithin(c, "camera_time_offset_s", 0.5, e->draw, &e->camera_time_offset_s);
  readErrorWithin(c, "wheel_time_offset_s", 0.5, e->draw, &e->wheel_time_offset_s);
  c.checkAllUsed();
}

// The sim.imu keys of the IMU error model.
const std::vector<std::string> kImuErrorKeys = {
    "gyro_scale_ppm",     "accel_scale_ppm", "gyro_misalignment_mrad", "accel_misalignment_mrad",
    "gyro_g_sensitivity", "gyro_bias_per_c", "accel_bias_per_c",       "temperature"};

void readImuErrors(const Config& imu, bool sigma, ImuErrors* e) {
  readErrorWithin(imu, "gyro_scale_ppm", 1e5, sigma, &e->gyro_scale_ppm);
  readErrorWithin(imu, "accel_scale_ppm", 1e5, sigma, &e->accel_scale_ppm);
  readErrorWithin(imu, "gyro_misalignment_mrad", 50.0, sigma, &e->gyro_misalignment_mrad);
  readErrorWithin(imu, "accel_misalignment_mrad", 50.0, sigma, &e->accel_misalignment_mrad);
  readErrorWithin(imu, "gyro_g_sensitivity", 0.01, sigma, &e->gyro_g_sensitivity);
  readErrorWithin(imu, "gyro_bias_per_c", 0.01, sigma, &e->gyro_bias_per_c);
  readErrorWithin(imu, "accel_bias_per_c", 0.1, sigma, &e->accel_bias_per_c);
  const Config temp = imu.optionalSection("temperature");
  ImuTemperature& T = e->temperature;
  temp.readOptional("start_c", T.start_c);
  T.end_c = T.start_c;
  temp.readOptional("end_c", T.end_c);
  temp.readOptional("ramp_s", T.ramp_s);
  if (!(T.start_c >= -60.0 && T.start_c <= 150.0))
    throw ConfigError(temp.where("start_c") + ": must be in -60..150 deg C");
  if (!(T.end_c >= -60.0 && T.end_c <= 150.0)) throw ConfigError(temp.where("end_c") + ": must be in -60..150 deg C");
  if (!(T.ramp_s > 0.0)) throw ConfigError(temp.where("ramp_s") + ": must be > 0");
  temp.checkAllUsed();
}

/// A replayed IMU stream is published as recorded: nothing of the IMU model (initial biases, error
/// model) applies to it.
void refuseImuModelOnARealImu(const Config& imu) {
  std::vector<std::string> keys = kImuErrorKeys;
  keys.insert(keys.end(), {"initial_gyro_bias", "initial_accel_bias"});
  for (const std::string& key : keys)
    if (imu.has(key))
      throw ConfigError(imu.where(key) +
                        ": a recorded trajectory publishes its real IMU samples unchanged; "
                        "the IMU model cannot be applied to them (remove the key, or drop sim.trajectory.imu to "
                        "synthesise the IMU from the recorded motion)");
}

/// The errors of this run: as configured, or drawn from the seed with the configured 1-sigmas.
void resolveErrors(SimulationSetup* s) {
  const SimOptions& o = s->options;
  const bool draw = o.calibration_errors.draw;
  s->calibration_errors = draw ? drawCalibrationErrors(o.calibration_errors, o.seed) : o.calibration_errors;
  s->imu_errors = draw ? drawImuErrors(o.imu_errors, o.seed) : o.imu_errors;
}

void readLidarEffects(const Config& lidar, LidarEffects* e) {
  lidar.readOptional("range_noise_per_m", e->range_noise_per_m);
  lidar.readOptional("noise_reflectivity_exponent", e->noise_reflectivity_exponent);
  lidar.readOptional("max_range_at_10pct", e->max_range_at_10pct);
  lidar.readOptional("detection_softness", e->detection_softness);
  std::vector<double> divergence;
  if (lidar.readOptional("beam_divergence_mrad", divergence)) {
    if (divergence.size() != 2)
      throw ConfigError(lidar.where("beam_divergence_mrad") + ": must be [horizontal, vertical]");
    e->beam_divergence_mrad = {{divergence[0], divergence[1]}};
  }
  lidar.readOptional("echo_separation_m", e->echo_separation_m);
  if (!(e->range_noise_per_m >= 0.0 && e->range_noise_per_m <= 0.1))
    throw ConfigError(lidar.where("range_noise_per_m") + ": must be in [0, 0.1]");
  if (!(e->noise_reflectivity_exponent >= 0.0 && e->noise_reflectivity_exponent <= 2.0))
    throw ConfigError(lidar.where("noise_reflectivity_exponent") + ": must be in [0, 2]");
  if (!(e->max_range_at_10pct >= 0.0)) throw ConfigError(lidar.where("max_range_at_10pct") + ": must be >= 0");
  if (!(e->detection_softness > 0.0 && e->detection_softness <= 2.0))
    throw ConfigError(lidar.where("detection_softness") + ": must be in (0, 2]");
  for (double d : e->beam_divergence_mrad)
    if (!(d >= 0.0 && d <= 50.0)) throw ConfigError(lidar.where("beam_divergence_mrad") + ": must be in [0, 50] mrad");
  if (!(e->echo_separation_m >= 0.0)) throw ConfigError(lidar.where("echo_separation_m") + ": must be >= 0");
}

/// sim.camera.auto_exposure: present = on.
void readAutoExposure(const Config& cam, CameraEffects* e) {
  if (!cam.has("auto_exposure")) return;
  const Config ae = cam.section("auto_exposure");
  AutoExposureOptions& a = e->auto_exposure;
  a.enabled = true;
  ae.readOptional("target_mean", a.target_mean);
  ae.readOptional("min_exposure", a.min_exposure);
  ae.readOptional("max_exposure", a.max_exposure);
  ae.readOptional("min_gain", a.min_gain);
  ae.readOptional("max_gain", a.max_gain);
  ae.readOptional("rate", a.rate);
  if (!(a.target_mean > 0.0 && a.target_mean < 255.0))
    throw ConfigError(ae.where("target_mean") + ": must be in (0, 255)");
  if (!(a.min_exposure > 0.0)) throw ConfigError(ae.where("min_exposure") + ": must be > 0");
  if (!(a.max_exposure >= a.min_exposure)) throw ConfigError(ae.where("max_exposure") + ": must be >= min_exposure");
  if (!(a.min_gain >= 1.0)) throw ConfigError(ae.where("min_gain") + ": must be >= 1");
  if (!(a.max_gain >= a.min_gain && a.max_gain <= 1000.0))
    throw ConfigError(ae.where("max_gain") + ": must be in [min_gain, 1000]");
  if (!(a.rate > 0.0 && a.rate <= 1.0)) throw ConfigError(ae.where("rate") + ": must be in (0, 1]");
  ae.checkAllUsed();
}

/// A [min, max] pair with lo <= min <= max <= hi.
void readRange(const Config& c, const std::string& key, double lo, double hi, double* min, double* max) {
  std::vector<double> v;
  if (!c.readOptional(key, v)) return;
  if (v.size() != 2 || !(lo <= v[0] && v[0] <= v[1] && v[1] <= hi))
    throw ConfigError(c.where(key) + ": must be [min, max] with " + number(lo) + " <= min <= max <= " + number(hi));
  *min = v[0];
  *max = v[1];
}

/// sim.wheel.slip: absent or rate_per_min 0 = off.
void readWheelSlip(const Config& slip, WheelSlipOptions* w) {
  slip.readOptional("rate_per_min", w->rate_per_min);
  if (!(w->rate_per_min >= 0.0 && w->rate_per_min <= 600.0))
    throw ConfigError(slip.where("rate_per_min") + ": must be in [0, 600] (0 = off)");
  readRange(slip, "duration_s", 1e-3, 60.0, &w->min_duration_s, &w->max_duration_s);
  readRange(slip, "spin", 0.0, 10.0, &w->min_spin, &w->max_spin);
  slip.readOptional("lock_probability", w->lock_probability);
  slip.readOptional("both_probability", w->both_probability);
  if (!(w->lock_probability >= 0.0 && w->lock_probability <= 1.0))
    throw ConfigError(slip.where("lock_probability") + ": must be in [0, 1]");
  if (!(w->both_probability >= 0.0 && w->both_probability <= 1.0))
    throw ConfigError(slip.where("both_probability") + ": must be in [0, 1]");
  slip.checkAllUsed();
}

/// sim.depth: the depth sensor's effects (rig.camera.depth).
void readDepthEffects(const Config& sim, const SensorRig& rig, DepthEffects* d) {
  const Config depth = sim.optionalSection("depth");
  if (!depth.isNull() && !(rig.camera && rig.camera->depth))
    throw ConfigError(sim.where("depth") + ": the rig's camera has no depth (rig.camera.depth)");
  depth.readOptional("noise_floor", d->noise_floor);
  depth.readOptional("noise_per_m2", d->noise_per_m2);
  depth.readOptional("min_range", d->min_range);
  depth.readOptional("max_range", d->max_range);
  depth.readOptional("edge_jump", d->edge_jump);
  depth.readOptional("edge_hole_px", d->edge_hole_px);
  depth.readOptional("hole_fraction", d->hole_fraction);
  depth.readOptional("hole_radius_px", d->hole_radius_px);
  if (!(d->noise_floor >= 0.0)) throw ConfigError(depth.where("noise_floor") + ": must be >= 0");
  if (!(d->noise_per_m2 >= 0.0)) throw ConfigError(depth.where("noise_per_m2") + ": must be >= 0");
  if (!(d->min_range >= 0.0)) throw ConfigError(depth.where("min_range") + ": must be >= 0");
  if (!(d->max_range > d->min_range && d->max_range <= 65.0))
    throw ConfigError(depth.where("max_range") + ": must be greater than min_range and at most 65 m (DEPTH16 in mm)");
  if (!(d->edge_jump > 0.0)) throw ConfigError(depth.where("edge_jump") + ": must be > 0");
  if (d->edge_hole_px < 0 || d->edge_hole_px > 50)
    throw ConfigError(depth.where("edge_hole_px") + ": must be in 0..50");
  if (!(d->hole_fraction >= 0.0 && d->hole_fraction < 0.9))
    throw ConfigError(depth.where("hole_fraction") + ": must be in [0, 0.9)");
  if (!(d->hole_radius_px >= 0.5 && d->hole_radius_px <= 200.0))
    throw ConfigError(depth.where("hole_radius_px") + ": must be in [0.5, 200]");
  depth.checkAllUsed();
}

void readSimOptions(const Config& sim, const SensorRig& rig, SimOptions* o) {
  sim.readOptional("start_time_s", o->start_time_s);
  sim.readOptional("duration_s", o->duration_s);
  sim.readOptional("ground_truth_rate_hz", o->ground_truth_rate_hz);
  int64_t seed = static_cast<int64_t>(o->seed);
  if (sim.readOptional("seed", seed)) {
    if (seed < 0) throw ConfigError(sim.where("seed") + ": must be >= 0");
    o->seed = static_cast<uint64_t>(seed);
  }
  sim.readOptional("threads", o->threads);
  if (!(o->start_time_s >= 0.0)) throw ConfigError(sim.where("start_time_s") + ": must be >= 0");
  if (!(o->duration_s > 0.0)) throw ConfigError(sim.where("duration_s") + ": must be > 0");
  if (!(o->ground_truth_rate_hz > 0.0)) throw ConfigError(sim.where("ground_truth_rate_hz") + ": must be > 0");
  if (o->threads < 1 || o->threads > 256) throw ConfigError(sim.where("threads") + ": must be in 1..256");

  readCalibrationErrors(sim.optionalSection("calibration_errors"), rig, &o->calibration_errors);
  const Config imu = sim.optionalSection("imu");
  imu.readOptional("initial_gyro_bias", o->initial_gyro_bias);
  imu.readOptional("initial_accel_bias", o->initial_accel_bias);
  readImuErrors(imu, o->calibration_errors.draw, &o->imu_errors);
  imu.checkAllUsed();

  const Config lidar = sim.optionalSection("lidar");
  if (!lidar.isNull() && !rig.lidar) throw ConfigError(sim.where("lidar") + ": the rig has no lidar");
  lidar.readOptional("columns", o->lidar.columns);
  lidar.readOptional("start_azimuth_deg", o->lidar.start_azimuth_deg);
  if (o->lidar.columns < 0 || o->lidar.columns > 100000)
    throw ConfigError(lidar.where("columns") + ": must be in 0..100000");
  readLidarEffects(lidar, &o->lidar_effects);
  lidar.checkAllUsed();

  const Config cam = sim.optionalSection("camera");
  if (!cam.isNull() && !rig.camera) throw ConfigError(sim.where("camera") + ": the rig has no camera");
  CameraEffects& e = o->camera;
  cam.readOptional("exposure_time", e.exposure_time);
  cam.readOptional("exposure_variation", e.exposure_variation);
  cam.readOptional("exposure_period_s", e.exposure_period_s);
  cam.readOptional("motion_blur_samples", e.motion_blur_samples);
  cam.readOptional("noise_std", e.noise_std);
  cam.readOptional("brightness", e.brightness);
  cam.readOptional("vignetting", e.vignetting);
  cam.readOptional("rolling_shutter_s", e.rolling_shutter_s);
  readAutoExposure(cam, &e);
  std::string trigger = "free";
  cam.readOptional("trigger", trigger);
  if (trigger == "free") {
    o->camera_trigger = CameraTrigger::kFree;
  } else if (trigger == "sweep_start" || trigger == "sweep_end") {
    o->camera_trigger = trigger == "sweep_start" ? CameraTrigger::kSweepStart : CameraTrigger::kSweepEnd;
    if (!rig.lidar) throw ConfigError(cam.where("trigger") + ": " + trigger + " needs a LiDAR to trigger the camera");
    if (rig.camera && std::abs(rig.camera->rate_hz - rig.lidar->rate_hz) > 1e-9)
      throw ConfigError(cam.where("trigger") + ": " + trigger + " fires once per sweep, so rig.camera.rate_hz (" +
                        std::to_string(rig.camera->rate_hz) + ") must equal rig.lidar.rate_hz (" +
                        std::to_string(rig.lidar->rate_hz) + ")");
  } else {
    throw ConfigError(cam.where("trigger") + ": '" + trigger + "' is not free, sweep_start or sweep_end");
  }
  if (!(e.exposure_time > 0.0)) throw ConfigError(cam.where("exposure_time") + ": must be > 0");
  if (!(e.exposure_variation >= 0.0 && e.exposure_variation < 1.0))
    throw ConfigError(cam.where("exposure_variation") + ": must be in [0, 1)");
  if (!(e.exposure_period_s > 0.0)) throw ConfigError(cam.where("exposure_period_s") + ": must be > 0");
  if (e.motion_blur_samples < 1 || e.motion_blur_samples > 64)
    throw ConfigError(cam.where("motion_blur_samples") + ": must be in 1..64");
  if (!(e.noise_std >= 0.0)) throw ConfigError(cam.where("noise_std") + ": must be >= 0");
  if (!(e.brightness > 0.0)) throw ConfigError(cam.where("brightness") + ": must be > 0");
  if (!(e.vignetting >= 0.0 && e.vignetting <= 1.0)) throw ConfigError(cam.where("vignetting") + ": must be in [0, 1]");
  if (!(e.rolling_shutter_s >= 0.0) || (rig.camera && !(e.rolling_shutter_s <= 1.0 / rig.camera->rate_hz)))
    throw ConfigError(cam.where("rolling_shutter_s") + ": must be in [0, 1 / rate_hz] (the readout fits in a frame)");
  cam.checkAllUsed();
  readDepthEffects(sim, rig, &o->depth);

  const Config wheel = sim.optionalSection("wheel");
  if (!wheel.isNull() && !rig.wheel) throw ConfigError(sim.where("wheel") + ": the rig has no wheel encoder");
  wheel.readOptional("left_scale", o->wheel_left_scale);
  wheel.readOptional("right_scale", o->wheel_right_scale);
  if (!(o->wheel_left_scale > 0.0)) throw ConfigError(wheel.where("left_scale") + ": must be > 0");
  if (!(o->wheel_right_scale > 0.0)) throw ConfigError(wheel.where("right_scale") + ": must be > 0");
  readWheelSlip(wheel.optionalSection("slip"), &o->wheel_slip);
  wheel.checkAllUsed();
}

void printDepthEffects(const DepthEffects& d, std::ostream& os) {
  os << "  depth: noise " << d.noise_floor * 1e3 << " mm + " << d.noise_per_m2 * 1e3 << " mm/m^2 z^2 ("
     << d.sigmaAt(1.0) * 1e3 << " mm at 1 m, " << d.sigmaAt(3.0) * 1e3 << " mm at 3 m), range " << d.min_range << ".."
     << d.max_range << " m, holes: " << d.edge_hole_px << " px at jumps over " << d.edge_jump * 100 << " %, blobs of "
     << d.hole_radius_px << " px over " << d.hole_fraction * 100 << " % of the image\n";
}

void printLidarEffects(const LidarEffects& e, std::ostream& os) {
  os << "  lidar effects:";
  if (!e.any()) os << " off";
  if (e.range_noise_per_m > 0.0)
    os << " range noise +" << e.range_noise_per_m * 100 << " cm/m (at 50 %, reflectivity exponent "
       << e.noise_reflectivity_exponent << ");";
  if (e.detection())
    os << " detection 90 % at " << e.max_range_at_10pct << " m for 10 % (softness " << e.detection_softness << ");";
  if (e.footprint())
    os << " beam " << e.beam_divergence_mrad[0] << " x " << e.beam_divergence_mrad[1]
       << " mrad FWHM, echoes merge within " << e.echo_separation_m << " m";
  os << "\n";
}

}  // namespace

SimulationSetup loadSimulation(const std::string& file, const SimOverrides& overrides) {
  SimulationSetup s = loadSimulation(Config::load(file, overrides.overlays), dirOf(file), overrides);
  s.config_file = file;
  for (const std::string& overlay : overrides.overlays) s.config_file += " + " + overlay;
  return s;
}

SimulationSetup loadSimulation(const Config& root, const std::string& base_dir, const SimOverrides& overrides) {
  root.checkKeysIn(kConfigSections);
  SimulationSetup s;
  s.config_file = root.file();
  s.rig = readSensorRig(root.section("rig"));
  if (s.rig.lidar) requireSimulatedLidar(root.section("rig").section("lidar"), s.rig.lidar->model);
  const Config sim = root.section("sim");
  readSimOptions(sim, s.rig, &s.options);

  if (sim.has("scene") == sim.has("scene_file"))
    throw ConfigError(sim.where("scene") + ": give exactly one of scene (a map) or scene_file (a path)");
  if (sim.has("scene")) {
    s.scene = readScene(sim.section("scene"));
    s.scene_source = "inline";
  } else {
    const std::string path = resolve(base_dir, sim.get<std::string>("scene_file"));
    Config scene_cfg = Config::fromString("", path);
    try {
      scene_cfg = Config::load(path);
    } catch (const ConfigError& e) {
      throw ConfigError(sim.where("scene_file") + ": " + e.what());
    }
    s.scene = readScene(scene_cfg);
    s.scene_source = path;
  }

  if (overrides.seed) s.options.seed = *overrides.seed;
  if (overrides.threads) s.options.threads = *overrides.threads;
  if (overrides.no_images) s.options.images = false;
  if (overrides.duration_s) {
    if (!(*overrides.duration_s > 0.0)) throw ConfigError("--duration: must be > 0");
    s.options.duration_s = *overrides.duration_s;
  }

  resolveErrors(&s);

  // a car's rear axle is where the wheels truly are
  const SensorRig mounted = trueRig(s.rig, s.calibration_errors);
  const Pose3 T_I_rear_axle = mounted.wheel ? mounted.wheel->T_I_B : Pose3::Identity();
  const double track_width = mounted.wheel ? mounted.wheel->track_width : CarTrajectoryOptions().track_width;
  TrajectoryConfig traj = readTrajectoryConfig(sim.section("trajectory"), s.rig.imu.gravity, base_dir, T_I_rear_axle,
                                               s.scene->terrain, track_width);
  s.trajectory = std::move(traj.trajectory);
  s.trajectory_description = traj.description;
  s.recorded = traj.recorded;
  s.recorded_imu = std::move(traj.recorded_imu);

  if (s.recorded) {
    if (s.replaysRecordedImu()) refuseImuModelOnARealImu(sim.optionalSection("imu"));
    if (sim.has("start_time_s"))
      throw ConfigError(sim.where("start_time_s") + ": a recorded trajectory takes its start time from the recording");
    // the span covered by the ground truth (and the IMU, when it is replayed), less the start offset
    const double gt0 = traj.recorded_start_stamp, gt1 = gt0 + s.trajectory->duration();
    double t0 = gt0, t1 = gt1;
    if (s.replaysRecordedImu()) {
      t0 = std::max(gt0, s.recorded_imu.front().stamp_ns * 1e-9);
      t1 = std::min(gt1, s.recorded_imu.back().stamp_ns * 1e-9);
      if (!(t1 > t0))
        throw ConfigError(sim.where("trajectory") + ": the ground truth and the IMU do not overlap in time");
    }
    t0 += traj.recorded_start_offset_s;
    if (!(t1 > t0))
      throw ConfigError(sim.section("trajectory").where("start_offset_s") +
                        ": starts at or after the end of the recording (" +
                        number(t1 - t0 + traj.recorded_start_offset_s) + " s available)");
    s.start_utime = static_cast<int64_t>(std::ceil(t0 * 1e6));
    s.trajectory_time_offset = static_cast<double>(s.start_utime) * 1e-6 - gt0;
    const double available = std::floor((t1 * 1e6 - static_cast<double>(s.start_utime))) * 1e-6;
    if (!sim.has("duration_s") && !overrides.duration_s) s.options.duration_s = available;
    s.options.duration_s = std::min(s.options.duration_s, available);
  } else {
    s.start_utime = static_cast<int64_t>(std::llround(s.options.start_time_s * 1e6));
  }
  sim.checkAllUsed();
  return s;
}

namespace {

void printExtrinsicError(const std::string& sensor, const ExtrinsicError& e, double time_offset_s, std::ostream& os) {
  os << "    " << sensor << ": T_err translation [" << e.translation.transpose() << "] m, rpy_deg ["
     << e.rpy_deg.transpose() << "], time offset error " << time_offset_s * 1e3 << " ms\n";
}

void printCalibrationErrors(const SimulationSetup& s, std::ostream& os) {
  const CalibrationErrors& e = s.calibration_errors;
  os << "  calibration errors (the TRUTH, never in rig:; T_I_X_true = T_I_X_rig * T_err, a message stamped t was "
        "measured at t + offset), "
     << (e.draw ? "drawn with seed " + std::to_string(s.options.seed) + " from the configured 1-sigmas"
                : "as configured")
     << ":\n";
  if (s.rig.lidar) printExtrinsicError("lidar", e.lidar, e.lidar_time_offset_s, os);
  if (s.rig.camera) printExtrinsicError("camera", e.camera, e.camera_time_offset_s, os);
  if (s.rig.wheel) printExtrinsicError("wheel", e.wheel, e.wheel_time_offset_s, os);
  os << "  the rig as rendered (truth):\n";
  printSensorRig(trueRig(s.rig, e), os);
}

void printImuErrors(const SimulationSetup& s, std::ostream& os) {
  const ImuErrors& e = s.imu_errors;
  os << "  IMU errors (the TRUTH" << (s.options.calibration_errors.draw ? ", drawn" : "") << "):\n    gyro scale ["
     << e.gyro_scale_ppm.transpose() << "] ppm, misalignment [" << e.gyro_misalignment_mrad.transpose()
     << "] mrad, g-sensitivity [" << e.gyro_g_sensitivity.transpose() << "] rad/s per m/s^2, bias ["
     << e.gyro_bias_per_c.transpose() << "] rad/s per C\n    accel scale [" << e.accel_scale_ppm.transpose()
     << "] ppm, misalignment [" << e.accel_misalignment_mrad.transpose() << "] mrad, bias ["
     << e.accel_bias_per_c.transpose() << "] m/s^2 per C\n    temperature " << e.temperature.start_c << " -> "
     << e.temperature.end_c << " C over " << e.temperature.ramp_s << " s\n";
}

}  // namespace

void printSimulation(const SimulationSetup& s, std::ostream& os) {
  const SimOptions& o = s.options;
  os << "config:     " << s.config_file << "\n";
  printSensorRig(s.rig, os);
  os << "sim:\n  start " << std::fixed << std::setprecision(6) << s.start_utime * 1e-6 << " s, duration "
     << std::setprecision(3) << o.duration_s << " s";
  os.unsetf(std::ios::floatfield);
  os << std::setprecision(6) << ", ground truth at " << o.ground_truth_rate_hz << " Hz, seed " << o.seed << ", "
     << o.threads << " threads\n";
  os << "  scene: " << s.scene_source << ": " << s.scene->objectCount() - s.scene->moverCount() << " objects, "
     << s.scene->textureCount() << " textures";
  if (s.scene->moverCount() > 0) os << ", " << s.scene->moverCount() << " moving objects";
  os << "\n";
  if (s.scene->terrain) {
    const Terrain& t = *s.scene->terrain;
    os << "  terrain: " << t.options().profiles.size() << " grade profiles, " << t.options().relief.size()
       << " relief waves, grades at most " << t.maxGrade() * 100.0 << " %, curvature at most " << t.maxCurvature()
       << " /m\n";
  }
  os << "  trajectory: " << s.trajectory_description << "\n";
  if (s.replaysRecordedImu())
    os << "  IMU: the recording's own samples, unchanged\n";
  else
    os << "  IMU initial bias: gyro [" << o.initial_gyro_bias.transpose() << "] rad/s, accel ["
       << o.initial_accel_bias.transpose() << "] m/s^2\n";
  if (s.rig.lidar)
    os << "  lidar: columns " << (o.lidar.columns ? std::to_string(o.lidar.columns) : std::string("model default"))
       << ", start azimuth " << o.lidar.start_azimuth_deg << " deg\n";
  if (s.rig.lidar) printLidarEffects(o.lidar_effects, os);
  if (s.rig.camera && !o.images) os << "  camera: images left out (--no-images); the other channels as with them\n";
  if (s.rig.camera)
    os << "  camera: exposure " << o.camera.exposure_time * 1e3 << " ms +-" << o.camera.exposure_variation * 100
       << "% over " << o.camera.exposure_period_s << " s, motion blur samples " << o.camera.motion_blur_samples
       << ", noise " << o.camera.noise_std << " DN, brightness " << o.camera.brightness << ", vignetting "
       << o.camera.vignetting << ", "
       << (o.camera_trigger == CameraTrigger::kFree         ? "free-running"
           : o.camera_trigger == CameraTrigger::kSweepStart ? "triggered at each sweep's start"
                                                            : "triggered at each sweep's end");
  if (s.rig.camera && o.camera.rolling_shutter_s > 0.0)
    os << ", rolling shutter readout " << o.camera.rolling_shutter_s * 1e3 << " ms";
  if (s.rig.camera) os << "\n";
  if (s.rig.camera && o.camera.auto_exposure.enabled) {
    const AutoExposureOptions& a = o.camera.auto_exposure;
    os << "  camera auto exposure: target mean " << a.target_mean << ", exposure " << a.min_exposure * 1e3 << ".."
       << a.max_exposure * 1e3 << " ms, gain " << a.min_gain << ".." << a.max_gain << ", rate " << a.rate
       << " per frame (exposure_variation drifts the scene light)\n";
  }
  if (s.rig.camera && s.rig.camera->depth) printDepthEffects(o.depth, os);
  if (s.rig.wheel)
    os << "  wheel: scale errors left " << o.wheel_left_scale << ", right " << o.wheel_right_scale << "\n";
  if (s.rig.wheel && o.wheel_slip.enabled()) {
    const WheelSlipOptions& w = o.wheel_slip;
    os << "  wheel slip: " << w.rate_per_min << " episodes per minute, " << w.min_duration_s << ".." << w.max_duration_s
       << " s each, " << w.both_probability * 100 << " % on both wheels, " << w.lock_probability * 100
       << " % locked (reads 0), else spinning +" << w.min_spin * 100 << ".." << w.max_spin * 100 << " %\n";
  }
  if (s.imu_errors.any()) printImuErrors(s, os);
  if (s.calibration_errors.any()) printCalibrationErrors(s, os);
}

}  // namespace livo::sim

namespace livo::sim {

namespace {
void jsonVec(std::ostream& os, const Vec3& v) { os << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]"; }
void jsonPose(std::ostream& os, const Pose3& T) {
  const Quat q(T.linear());
  os << "{\"translation\": ";
  jsonVec(os, T.translation());
  os << ", \"rotation_wxyz\": [" << q.w() << ", " << q.x() << ", " << q.y() << ", " << q.z() << "]}";
}
void jsonError(std::ostream& os, const ExtrinsicError& e, double time_offset_s) {
  os << "{\"rotation_vector\": ";
  jsonVec(os, so3::Log(Mat3(e.transform().linear())));
  os << ", \"translation\": ";
  jsonVec(os, e.translation);
  os << ", \"time_offset_s\": " << time_offset_s << "}";
}
}  // namespace

std::string truthJson(const SimulationSetup& s) {
  std::ostringstream os;
  os << std::setprecision(12) << "{\"seed\": " << s.options.seed << ", \"calibration_errors\": {\"lidar\": ";
  const CalibrationErrors& e = s.calibration_errors;
  jsonError(os, e.lidar, e.lidar_time_offset_s);
  os << ", \"camera\": ";
  jsonError(os, e.camera, e.camera_time_offset_s);
  os << "}, \"nominal\": {";
  const SensorRig truth = trueRig(s.rig, e);
  const char* sep = "";
  if (s.rig.lidar) {
    os << "\"T_I_L\": ";
    jsonPose(os, s.rig.lidar->T_I_L);
    sep = ", ";
  }
  if (s.rig.camera) {
    os << sep << "\"T_I_C\": ";
    jsonPose(os, s.rig.camera->T_I_C);
  }
  os << "}, \"true\": {";
  sep = "";
  if (truth.lidar) {
    os << "\"T_I_L\": ";
    jsonPose(os, truth.lidar->T_I_L);
    sep = ", ";
  }
  if (truth.camera) {
    os << sep << "\"T_I_C\": ";
    jsonPose(os, truth.camera->T_I_C);
  }
  os << "}}\n";
  return os.str();
}

}  // namespace livo::sim
