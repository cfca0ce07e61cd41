#include "livo/lio/lio_config.hpp"

#include <cmath>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "livo/sensor_rig.hpp"
#include "livo/text_format.hpp"

namespace livo::lio {

namespace {
void readRig(const Config& rig, LioNodeOptions* o) {
  LioOptions& l = o->core;
  // The rig is validated as every other process validates it (a model name, ranges and noise the
  // LIO itself does not read are still errors here); the LIO then reads what it uses.
  const SensorRig sensors = readSensorRig(rig);
  auto stdOf = [](const CalibrationUncertainty& u) {
    return CalibrationStd{u.rotation_deg * M_PI / 180.0, u.translation, u.time_offset_s};
  };
  if (sensors.lidar) l.lidar_calibration_std = stdOf(sensors.lidar->calibration_std);
  if (sensors.camera) {
    l.camera_T_I_C = sensors.camera->T_I_C;
    l.camera_calibration_std = stdOf(sensors.camera->calibration_std);
  }
  const Config ch = rig.optionalSection("channels");
  ch.readOptional("imu", o->imu_channel);
  ch.readOptional("lidar", o->lidar_channel);
  ch.readOptional("wheel", o->wheel_channel);
  ch.readOptional("camera", o->camera_channel);
  ch.ignore("ground_truth");

  const Config imu = rig.section("imu");
  imu.ignore("rate_hz");
  imu.read("gyro_noise_density", l.imu_noise.gyro_noise_density);
  imu.read("gyro_random_walk", l.imu_noise.gyro_random_walk);
  imu.read("accel_noise_density", l.imu_noise.accel_noise_density);
  imu.read("accel_random_walk", l.imu_noise.accel_random_walk);
  imu.readOptional("gyro_scale_std", l.imu_noise.gyro_scale_std);
  imu.readOptional("gyro_misalignment_std", l.imu_noise.gyro_misalignment_std);
  imu.readOptional("accel_scale_std", l.imu_noise.accel_scale_std);
  imu.readOptional("accel_misalignment_std", l.imu_noise.accel_misalignment_std);
  if (!(l.imu_noise.accel_scale_std >= 0.0)) throw ConfigError(imu.where("accel_scale_std") + ": must be >= 0");
  if (!(l.imu_noise.accel_misalignment_std >= 0.0))
    throw ConfigError(imu.where("accel_misalignment_std") + ": must be >= 0");
  if (!(l.imu_noise.gyro_scale_std >= 0.0)) throw ConfigError(imu.where("gyro_scale_std") + ": must be >= 0");
  if (!(l.imu_noise.gyro_misalignment_std >= 0.0))
    throw ConfigError(imu.where("gyro_misalignment_std") + ": must be >= 0");
  imu.readOptional("gravity", l.init.gravity);

  const Config lidar = rig.section("lidar");
  lidar.ignore("model");
  double sweep_rate_hz = 0.0;
  if (lidar.readOptional("rate_hz", sweep_rate_hz) && sweep_rate_hz > 0.0)
    l.imu_noise.systematic_error_window_s = 1.0 / sweep_rate_hz;  // the attitude is corrected once a sweep
  lidar.ignore("dropout_probability");
  lidar.readOptional("min_range", l.min_range);
  lidar.readOptional("max_range", l.max_range);
  double range_noise = 0.0;
  if (lidar.readOptional("range_noise_std", range_noise) && range_noise > 0.0) {
    l.matching = matchingForRangeNoise(range_noise, l.matching);  // lio.matching.* may still override
    l.planes.range_noise_std = range_noise;
  }
  lidar.read("T_I_L", l.extrinsics.T_I_L);

  const Config cam = rig.optionalSection("camera");
  if (!cam.isNull()) {
    for (const std::string& key : cam.keys())
      if (key != "time_offset_s" && key != "rate_hz") cam.ignore(key);  // the VIO and colouring read the model
    cam.readOptional("time_offset_s", o->camera_time_offset_s);
    cam.readOptional("rate_hz", o->camera_rate_hz);
    if (!(o->camera_rate_hz > 0.0)) throw ConfigError(cam.where("rate_hz") + ": must be > 0");
  }
  const Config wheel = rig.optionalSection("wheel");
  if (!wheel.isNull()) {
    l.wheel.enabled = true;
    wheel.ignore("rate_hz");
    wheel.readOptional("track_width", l.wheel.track_width);
    wheel.readOptional("speed_noise_std", l.wheel.speed_noise_std);
    wheel.readOptional("T_I_B", l.wheel.T_I_B);
  }
}

// lio.*: a reader per section, in the order the keys were always read (the first malformed value
// is the one reported), then the ranges.
void readNodeKeys(const Config& c, LioNodeOptions* o) {
  c.readOptional("name", o->name);
  c.readOptional("publish_registered_scan", o->publish_registered_scan);
  c.readOptional("imu_reorder_window_s", o->imu_reorder_window_s);
  c.readOptional("wheel_max_wait_s", o->wheel_max_wait_s);
  c.readOptional("clock_reset_s", o->clock_reset_s);
  c.readOptional("clock_jump_s", o->clock_jump_s);
  c.readOptional("imu_max_angular_velocity", o->imu_max_angular_velocity);
  c.readOptional("imu_max_acceleration", o->imu_max_acceleration);
  c.readOptional("max_pending_scans", o->max_pending_scans);
  c.readOptional("camera_handoff", o->camera_handoff);
  c.readOptional("output_dir", o->output_dir);
  c.readOptional("posterior_max_wait_s", o->posterior_max_wait_s);
  c.readOptional("image_lidar_wait_s", o->image_lidar_wait_s);
  c.readOptional("image_max_wait_s", o->image_max_wait_s);
}

void readOutputChannels(const Config& out, LioNodeOptions* o) {
  out.readOptional("state_posterior", o->state_posterior_channel);
  out.readOptional("loop_correction", o->loop_correction_channel);
  out.readOptional("odometry", o->odometry_channel);
  out.readOptional("registered_scan", o->registered_scan_channel);
  out.readOptional("keyframe", o->keyframe_channel);
  out.readOptional("state_prior", o->state_prior_channel);
}

void readInit(const Config& init, ImuInitOptions* i) {
  std::string mode;
  if (init.readOptional("mode", mode)) {
    if (mode == "auto")
      i->mode = ImuInitOptions::Mode::kAuto;
    else if (mode == "static")
      i->mode = ImuInitOptions::Mode::kStatic;
    else if (mode == "moving")
      i->mode = ImuInitOptions::Mode::kMoving;
    else
      throw ConfigError(init.where("mode") + ": expected auto, static or moving, got '" + mode + "'");
  }
  init.readOptional("window_s", i->window_s);
  init.readOptional("max_gyro_std", i->max_gyro_std);
  init.readOptional("max_accel_std", i->max_accel_std);
  init.readOptional("moving_vel_std", i->moving_vel_std);
}

void readCalibrationEstimate(const Config& cal, CalibrationEstimation* e) {
  cal.readOptional("lidar_rotation", e->lidar_rotation);
  cal.readOptional("lidar_translation", e->lidar_translation);
  cal.readOptional("lidar_time", e->lidar_time);
  cal.readOptional("camera_rotation", e->camera_rotation);
  cal.readOptional("camera_translation", e->camera_translation);
  cal.readOptional("camera_time", e->camera_time);
  std::string imu_axes;
  if (cal.readOptional("imu_axes", imu_axes)) {
    using A = CalibrationEstimation::ImuAxes;
    if (imu_axes == "budget")
      e->imu_axes = A::kBudget;
    else if (imu_axes == "consider")
      e->imu_axes = A::kConsider;
    else if (imu_axes == "estimate")
      e->imu_axes = A::kEstimate;
    else
      throw ConfigError(cal.where("imu_axes") + ": must be budget, consider or estimate (got '" + imu_axes + "')");
  }
}

void readCoreKeys(const Config& c, LioOptions* l) {
  c.readOptional("point_stride", l->point_stride);
  c.readOptional("scan_voxel_size", l->scan_voxel_size);
  c.readOptional("min_points", l->min_points);
  c.readOptional("min_residuals", l->min_residuals);
  c.readOptional("search_threads", l->search_threads);
  c.readOptional("max_imu_gap_s", l->max_imu_gap_s);
  c.readOptional("reset_imu_gap_s", l->reset_imu_gap_s);
  c.readOptional("gap_rate_std", l->gap_rate_std);
  c.readOptional("max_position_jump", l->max_position_jump);
  c.readOptional("max_imu_backlog_s", l->max_imu_backlog_s);
  c.readOptional("reseed_after_s", l->reseed_after_s);
}

void readPlanes(const Config& planes, VoxelPlanesOptions* p) {
  planes.readOptional("enabled", p->enabled);
  planes.readOptional("cell_size", p->cell_size);
  planes.readOptional("max_points", p->max_points);
  planes.readOptional("min_points", p->min_points);
  planes.readOptional("point_stride", p->point_stride);
  planes.readOptional("max_std", p->max_std);
  planes.readOptional("max_normal_angle", p->max_normal_angle);
  planes.readOptional("refresh_range_ratio", p->refresh_range_ratio);
  planes.readOptional("max_variance_ratio", p->max_variance_ratio);
  planes.readOptional("model_std", p->model_std);
  planes.readOptional("max_range", p->max_range);
}

void readSeenThrough(const Config& seen, SeenThroughOptions* s) {
  seen.readOptional("enabled", s->enabled);
  seen.readOptional("beam_radius", s->beam_radius);
  seen.readOptional("beam_divergence", s->beam_divergence);
  seen.readOptional("end_margin", s->end_margin);
  seen.readOptional("end_margin_fraction", s->end_margin_fraction);
  seen.readOptional("min_range", s->min_range);
  seen.readOptional("max_range", s->max_range);
  seen.readOptional("misses_to_remove", s->misses_to_remove);
  seen.readOptional("ray_stride", s->ray_stride);
}

void readMap(const Config& map, LioOptions* l) {
  map.readOptional("voxel_size", l->map.voxel_size);
  map.readOptional("max_points_per_voxel", l->map.max_points_per_voxel);
  map.readOptional("min_point_distance", l->map.min_point_distance);
  map.readOptional("seen_again_distance", l->map.seen_again_distance);
  map.readOptional("refresh_range_ratio", l->map.refresh_range_ratio);
  readPlanes(map.optionalSection("planes"), &l->planes);
  map.readOptional("radius", l->map_radius);
  map.readOptional("prune_distance", l->map_prune_distance);
  std::string on_correction = l->map_on_loop_correction == LioOptions::OnLoopCorrection::kMove ? "move" : "rebuild";
  map.readOptional("on_loop_correction", on_correction);
  if (on_correction != "move" && on_correction != "rebuild")
    throw ConfigError(map.where("on_loop_correction") + ": must be move or rebuild (not " + on_correction + ")");
  l->map_on_loop_correction =
      on_correction == "move" ? LioOptions::OnLoopCorrection::kMove : LioOptions::OnLoopCorrection::kRebuild;
  readSeenThrough(map.optionalSection("seen_through"), &l->seen_through);
}

void readMatching(const Config& m, ScanToMapOptions* o) {
  m.readOptional("num_neighbors", o->plane.num_neighbors);
  m.readOptional("max_neighbor_distance", o->plane.max_neighbor_distance);
  m.readOptional("max_plane_thickness", o->plane.max_plane_thickness);
  m.readOptional("min_planarity", o->plane.min_planarity);
  m.readOptional("point_noise_std", o->point_noise_std);
  m.readOptional("residual_range_factor", o->residual_range_factor);
  m.readOptional("research_distance", o->research_distance);
  m.readOptional("robust_scale", o->robust_scale);
  m.readOptional("degeneracy_threshold", o->degeneracy_threshold);
  m.readOptional("degeneracy_lever_arm", o->degeneracy_lever_arm);
  m.readOptional("remove_degenerate", o->remove_degenerate);
  const Config floor = m.optionalSection("registration_floor");
  double floor_rotation_deg = o->registration_floor_rotation * 180.0 / M_PI;
  floor.readOptional("rotation_deg", floor_rotation_deg);
  floor.readOptional("translation", o->registration_floor_translation);
  o->registration_floor_rotation = floor_rotation_deg * M_PI / 180.0;
  if (!(floor_rotation_deg >= 0.0 && floor_rotation_deg <= 1.0))
    throw ConfigError(floor.where("rotation_deg") + ": must be in [0, 1] deg");
  if (!(o->registration_floor_translation >= 0.0 && o->registration_floor_translation <= 0.1))
    throw ConfigError(floor.where("translation") + ": must be in [0, 0.1] m");
}

void readKeyframe(const Config& k, LioOptions* l) {
  k.readOptional("min_distance", l->keyframe.min_distance);
  k.readOptional("min_angle_deg", l->keyframe.min_angle_deg);
  k.readOptional("cloud_voxel", l->keyframe.cloud_voxel);
  int max_stored = static_cast<int>(l->max_stored_keyframes);
  k.readOptional("max_stored", max_stored);
  l->max_stored_keyframes = static_cast<size_t>(std::max(1, max_stored));
}

void readWheelScale(const Config& ws, WheelScaleOptions* s) {
  ws.readOptional("enabled", s->enabled);
  ws.readOptional("prior_std", s->prior_std);
  ws.readOptional("random_walk", s->random_walk);
  ws.readOptional("displacement_noise_std", s->displacement_noise_std);
  ws.readOptional("min_speed", s->min_speed);
  ws.readOptional("gate_chi2", s->gate_chi2);
  ws.readOptional("max_interval_s", s->max_interval_s);
  auto inRange = [&](bool ok, const char* key, const char* what) {
    if (!ok) throw ConfigError(ws.where(key) + ": " + what);
  };
  inRange(s->prior_std >= 0.0 && s->prior_std <= 0.5, "prior_std", "must be in [0, 0.5]");
  inRange(s->random_walk >= 0.0 && s->random_walk <= 0.01, "random_walk", "must be in [0, 0.01] 1/sqrt(s)");
  inRange(s->displacement_noise_std > 0.0 && s->displacement_noise_std <= 1.0, "displacement_noise_std",
          "must be in (0, 1] m");
  inRange(s->min_speed > 0.0, "min_speed", "must be positive");
  inRange(s->gate_chi2 > 0.0, "gate_chi2", "must be positive");
  inRange(s->max_interval_s > 0.0 && s->max_interval_s <= 10.0, "max_interval_s", "must be in (0, 10] s");
}

void readWheel(const Config& w, LioOptions* l) {
  w.readOptional("enabled", l->wheel.enabled);
  w.readOptional("lateral_noise_std", l->wheel.lateral_noise_std);
  w.readOptional("vertical_noise_std", l->wheel.vertical_noise_std);
  w.readOptional("max_sample_gap_s", l->wheel.max_sample_gap_s);
  w.readOptional("gate_chi2", l->wheel.gate_chi2);
  readWheelScale(w.optionalSection("scale"), &l->wheel_scale);
}

/// The ranges of lio.* once read; every check names the key it is about (c.where: lio.KEY, with its section).
void checkRanges(const Config& c, const LioNodeOptions& o) {
  const LioOptions& l = o.core;
  auto check = [&](bool ok, const std::string& key, const char* what) {
    if (!ok) throw ConfigError(c.where(key) + ": " + what);
  };
  check(l.map.voxel_size > 0, "map.voxel_size", "must be positive");
  check(l.map.max_points_per_voxel > 0, "map.max_points_per_voxel", "must be positive");
  check(l.map.refresh_range_ratio >= 0.0 && l.map.refresh_range_ratio < 1.0, "map.refresh_range_ratio",
        "must be in [0, 1)");
  try {
    VoxelPlanes check_planes(l.planes);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(c.where("map") + ".planes: " + e.what());
  }
  const SeenThroughOptions& st = l.seen_through;
  check(st.beam_radius >= 0, "map.seen_through.beam_radius", "must be >= 0");
  check(st.beam_divergence >= 0, "map.seen_through.beam_divergence", "must be >= 0");
  check(st.end_margin >= 0, "map.seen_through.end_margin", "must be >= 0");
  check(st.end_margin_fraction >= 0, "map.seen_through.end_margin_fraction", "must be >= 0");
  check(st.min_range >= 0, "map.seen_through.min_range", "must be >= 0");
  check(st.max_range > st.min_range, "map.seen_through.max_range", "must be above map.seen_through.min_range");
  check(st.misses_to_remove >= 1 && st.misses_to_remove <= 100, "map.seen_through.misses_to_remove",
        "must be 1 to 100");
  check(st.ray_stride >= 1, "map.seen_through.ray_stride", "must be >= 1");
  check(l.scan_voxel_size > 0, "scan_voxel_size", "must be positive");
  check(l.point_stride > 0, "point_stride", "must be positive");
  check(l.search_threads >= 1 && l.search_threads <= 64, "search_threads", "must be 1 to 64");
  check(l.matching.plane.num_neighbors >= 3 && l.matching.plane.num_neighbors <= 32, "matching.num_neighbors",
        "must be 3 to 32");
  check(l.matching.point_noise_std > 0, "matching.point_noise_std", "must be positive");
  check(l.esikf.max_iterations > 0, "esikf.max_iterations", "must be positive");
  check(l.init.window_s > 0, "init.window_s", "must be positive");
  check(o.posterior_max_wait_s > 0, "posterior_max_wait_s", "must be positive");
  check(o.image_lidar_wait_s > 0, "image_lidar_wait_s", "must be positive");
  check(o.image_max_wait_s >= 0, "image_max_wait_s", "must be >= 0");
  check(l.max_imu_backlog_s > 0, "max_imu_backlog_s", "must be positive");
  check(l.reseed_after_s > 0, "reseed_after_s", "must be positive");
}

void readLio(const Config& c, LioNodeOptions* o) {
  LioOptions& l = o->core;
  readNodeKeys(c, o);
  readOutputChannels(c.optionalSection("channels"), o);
  readInit(c.optionalSection("init"), &l.init);
  c.readOptional("lidar_time_offset_s", l.extrinsics.time_offset_s);
  readCalibrationEstimate(c.optionalSection("calibration").optionalSection("estimate"), &l.calibration);
  readCoreKeys(c, &l);
  readMap(c.optionalSection("map"), &l);
  readMatching(c.optionalSection("matching"), &l.matching);
  const Config e = c.optionalSection("esikf");
  e.readOptional("max_iterations", l.esikf.max_iterations);
  e.readOptional("convergence_rot", l.esikf.convergence_rot);
  e.readOptional("convergence_pos", l.esikf.convergence_pos);
  readKeyframe(c.optionalSection("keyframe"), &l);
  readWheel(c.optionalSection("wheel"), &l);
  checkRanges(c, *o);
}
}  // namespace

LioNodeOptions readLioNodeOptions(const Config& root) {
  LioNodeOptions o;
  readRig(root.section("rig"), &o);
  const Config lio = root.optionalSection("lio");
  if (!lio.isNull()) {
    readLio(lio, &o);
    lio.checkAllUsed();
  }
  return o;
}

namespace {
std::string describe(const CalibrationStd& s) {
  if (!s.any()) return "held at the rig's";
  std::ostringstream os;
  os << s.rotation * 180.0 / M_PI << " / " << s.translation << " / " << s.time * 1e3;
  return os.str();
}
// how the IMU's axis errors enter the filter (CalibrationEstimation::imu_axes)
std::string imuAxesModel(const LioOptions& l) {
  switch (l.calibration.imu_axes) {
    case CalibrationEstimation::ImuAxes::kEstimate: return "estimated";
    case CalibrationEstimation::ImuAxes::kConsider: return "considered";
    case CalibrationEstimation::ImuAxes::kBudget: break;
  }
  return "the gyro's budgeted per " + formatSignificant(l.imu_noise.systematic_error_window_s) + " s sweep";
}
}  // namespace

void printOptions(const LioNodeOptions& o, std::ostream& os) {
  const LioOptions& l = o.core;
  const Vec3 t = l.extrinsics.T_I_L.translation();
  os << "[" << o.name << "] inputs " << o.imu_channel << ", " << o.lidar_channel
     << (l.wheel.enabled ? ", " + o.wheel_channel : std::string()) << ", " << o.state_posterior_channel << ", "
     << o.loop_correction_channel << "; outputs " << o.odometry_channel << ", " << o.registered_scan_channel << ", "
     << o.keyframe_channel << "\n"
     << "  imu noise: gyro " << l.imu_noise.gyro_noise_density << " / " << l.imu_noise.gyro_random_walk << ", accel "
     << l.imu_noise.accel_noise_density << " / " << l.imu_noise.accel_random_walk << ", gyro scale "
     << l.imu_noise.gyro_scale_std << " and misalignment " << l.imu_noise.gyro_misalignment_std << " rad, accel "
     << l.imu_noise.accel_scale_std << " and " << l.imu_noise.accel_misalignment_std << " rad (" << imuAxesModel(l)
     << ")"
     << ", gravity " << l.init.gravity << ", init window " << l.init.window_s << " s\n"
     << "  T_I_L translation [" << t.transpose() << "], time offset " << l.extrinsics.time_offset_s << " s, range ["
     << l.min_range << ", " << l.max_range << "] m\n"
     << "  calibration in the filter (1-sigma rotation deg / translation m / time ms): LiDAR "
     << describe(l.lidar_calibration_std) << ", camera " << describe(l.camera_calibration_std) << "\n"
     << "  scan voxel " << l.scan_voxel_size << " m, stride " << l.point_stride << "; map voxel " << l.map.voxel_size
     << " m x " << l.map.max_points_per_voxel << " points, spacing " << l.map.min_point_distance << " m, radius "
     << l.map_radius << " m, "
     << (l.map_on_loop_correction == LioOptions::OnLoopCorrection::kMove ? "moved" : "rebuilt from keyframes")
     << " on a loop correction"
     << (l.planes.enabled ? "; voxel planes of " + formatSignificant(l.planes.cell_size) + " m cells (range noise " +
                                formatSignificant(l.planes.range_noise_std) + " m)"
                          : std::string())
     << "\n"
     << "  planes: k " << l.matching.plane.num_neighbors << ", thickness " << l.matching.plane.max_plane_thickness
     << " m; residual sigma " << l.matching.point_noise_std << " m, registration floor "
     << l.matching.registration_floor_rotation * 180.0 / M_PI << " deg / " << l.matching.registration_floor_translation
     << " m, Cauchy scale " << l.matching.robust_scale << " m; iterations " << l.esikf.max_iterations
     << "; degeneracy threshold " << l.matching.degeneracy_threshold << "; " << l.search_threads
     << (l.search_threads == 1 ? " search thread" : " search threads") << "\n"
     << "  camera hand-off "
     << (o.camera_handoff ? "on (" + o.camera_channel + " -> " + o.state_prior_channel + ")" : std::string("off"))
     << "\n"
     << "  keyframes every " << l.keyframe.min_distance << " m / " << l.keyframe.min_angle_deg << " deg; wheel "
     << (l.wheel.enabled ? "on" : "off");
  if (l.wheel.enabled) {
    const WheelScaleOptions& s = l.wheel_scale;
    if (s.enabled)
      os << " (scale calibration: prior 1 +/- " << s.prior_std << ", random walk " << s.random_walk
         << "/sqrt(s), displacement noise " << s.displacement_noise_std << " m, above " << s.min_speed << " m/s)";
    else
      os << " (scale calibration off)";
  }
  os << std::endl;
}

}  // namespace livo::lio
