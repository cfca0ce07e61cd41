#include "livo/vio/vio_config.hpp"

#include <ostream>
#include <stdexcept>

namespace livo::vio {

namespace {

void readChannels(const Config& ch, VioNodeOptions* n) {
  ch.readOptional("camera", n->camera_channel);
  ch.readOptional("state_prior", n->state_prior_channel);
  ch.readOptional("state_posterior", n->state_posterior_channel);
  ch.readOptional("registered_scan", n->registered_scan_channel);
  ch.readOptional("loop_correction", n->loop_correction_channel);
}

void readImageCheck(const Config& img, ImageCheckOptions* o) {
  img.readOptional("dark_level", o->dark_level);
  img.readOptional("bright_level", o->bright_level);
  img.readOptional("max_dark_fraction", o->max_dark_fraction);
  img.readOptional("max_bright_fraction", o->max_bright_fraction);
}

void readMap(const Config& map, MapOptions* o) {
  map.readOptional("voxel_size", o->voxel_size);
  map.readOptional("radius", o->radius);
  map.readOptional("max_points", o->max_points);
  map.readOptional("max_observations", o->max_observations);
  map.readOptional("recent_scans", o->recent_scans);
  map.readOptional("plane_snap_max_rms", o->plane_snap_max_rms);
  map.readOptional("plane_snap_min_points", o->plane_snap_min_points);
  map.readOptional("normal_max_rms", o->normal_max_rms);
  map.readOptional("normal_min_points", o->normal_min_points);
}

void readSelection(const Config& sel, SelectionOptions* o) {
  sel.readOptional("grid_cell_px", o->grid_cell_px);
  sel.readOptional("min_depth", o->min_depth);
  sel.readOptional("max_depth", o->max_depth);
  sel.readOptional("depth_cell_px", o->depth_cell_px);
  sel.readOptional("occlusion_tolerance", o->occlusion_tolerance);
  sel.readOptional("occlusion_tolerance_rel", o->occlusion_tolerance_rel);
  sel.readOptional("max_view_angle_deg", o->max_view_angle_deg);
  sel.readOptional("depth_edge_radius_px", o->depth_edge_radius_px);
  sel.readOptional("depth_edge_tolerance", o->depth_edge_tolerance);
  sel.readOptional("depth_edge_tolerance_rel", o->depth_edge_tolerance_rel);
  sel.readOptional("view_angle_weight", o->view_angle_weight);
  sel.readOptional("error_weight", o->error_weight);
  sel.readOptional("age_weight", o->age_weight);
}

void readPhotometric(const Config& ph, PhotometricOptions* o) {
  ph.readOptional("pyramid_levels", o->pyramid_levels);
  ph.readOptional("noise_std", o->noise_std);
  ph.readOptional("huber_threshold", o->huber_threshold);
  ph.readOptional("affine_brightness", o->affine_brightness);
  ph.readOptional("min_gain", o->min_gain);
  ph.readOptional("max_gain", o->max_gain);
  ph.readOptional("min_ncc", o->min_ncc);
  ph.readOptional("point_std", o->point_std);
  ph.readOptional("reference_rotation_std_deg", o->reference_rotation_std_deg);
  ph.readOptional("reference_translation_std", o->reference_translation_std);
  ph.readOptional("reference_translation_per_m", o->reference_translation_per_m);
}

void readUpdate(const Config& up, UpdateOptions* o) {
  up.readOptional("max_iterations", o->max_iterations);
  up.readOptional("convergence_rot", o->convergence_rot);
  up.readOptional("convergence_pos", o->convergence_pos);
  up.readOptional("min_patches", o->min_patches);
  up.readOptional("gate_probability", o->gate_probability);
  up.readOptional("calibration_information_scale", o->calibration_information_scale);
  up.readOptional("max_step_pos", o->max_step_pos);
  up.readOptional("max_step_rot_deg", o->max_step_rot_deg);
  up.readOptional("reference_floor", o->reference_floor);
  up.readOptional("gyro_bias_std_to_update", o->gyro_bias_std_to_update);
  if (up.has("covariance")) {
    const std::string c = up.get<std::string>("covariance");
    if (c == "full")
      o->covariance = CovarianceUpdate::kFull;
    else if (c == "beyond_prior")
      o->covariance = CovarianceUpdate::kBeyondPrior;
    else
      throw ConfigError(up.where("covariance") + ": '" + c + "' is neither full nor beyond_prior");
  }
}

void readNewPoints(const Config& np, MaintenanceOptions* o) {
  np.readOptional("cell_px", o->new_point_cell_px);
  np.readOptional("min_gradient", o->min_gradient);
  np.readOptional("max_per_image", o->max_new_points);
}

void readRefresh(const Config& rf, MaintenanceOptions* o) {
  rf.readOptional("angle_deg", o->refresh_angle_deg);
  rf.readOptional("distance_ratio", o->refresh_distance_ratio);
  rf.readOptional("error", o->refresh_error);
  rf.readOptional("min_ncc", o->outlier_ncc);
}

// The node's own ranges (the core's are validate()'s).
void checkNodeRanges(const Config& c, const VioNodeOptions& n) {
  auto require = [&](bool ok, const std::string& key, const char* what) {
    if (!ok) throw ConfigError(c.where(key) + ": " + what);
  };
  require(n.time_tolerance_s >= 0.0, "time_tolerance_s", "must be >= 0");
  require(n.image_buffer_s > 0.0, "image_buffer_s", "must be > 0");
  require(n.max_buffered_images >= 1, "max_buffered_images", "must be >= 1");
  require(n.image_check.max_dark_fraction > 0.0 && n.image_check.max_dark_fraction <= 1.0 &&
              n.image_check.max_bright_fraction > 0.0 && n.image_check.max_bright_fraction <= 1.0,
          "image", "fractions must be in (0, 1]");
  require(n.image_check.dark_level < n.image_check.bright_level, "image", "dark_level must be below bright_level");
}

void readVio(const Config& c, VioNodeOptions* n) {
  VioOptions& o = n->core;
  c.readOptional("name", n->name);
  readChannels(c.optionalSection("channels"), n);
  c.readOptional("time_tolerance_s", n->time_tolerance_s);
  c.readOptional("image_buffer_s", n->image_buffer_s);
  c.readOptional("max_buffered_images", n->max_buffered_images);
  readImageCheck(c.optionalSection("image"), &n->image_check);
  readMap(c.optionalSection("map"), &o.map);
  readSelection(c.optionalSection("selection"), &o.selection);
  readPhotometric(c.optionalSection("photometric"), &o.photometric);
  readUpdate(c.optionalSection("update"), &o.update);
  readNewPoints(c.optionalSection("new_points"), &o.maintenance);
  readRefresh(c.optionalSection("refresh"), &o.maintenance);
  checkNodeRanges(c, *n);
}

}  // namespace

VioNodeOptions readVioNodeOptions(const Config& root) {
  VioNodeOptions n;
  const Config rig = root.section("rig");
  const SensorRig sensor_rig = readSensorRig(rig);
  if (!sensor_rig.camera) throw ConfigError(rig.where("camera") + ": livo-vio needs a camera in the rig");
  n.camera = *sensor_rig.camera;
  n.camera_time_offset_s = n.camera.time_offset_s;
  n.camera_channel = sensor_rig.channels.camera;
  // the map points are LiDAR returns: known to the LiDAR's range noise
  if (sensor_rig.lidar) n.core.photometric.point_std = sensor_rig.lidar->range_noise_std;
  const Config vio = root.optionalSection("vio");
  if (!vio.isNull()) {
    readVio(vio, &n);
    vio.checkAllUsed();
  }
  try {
    validate(n.core);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(root.file() + ": vio." + e.what());
  }
  return n;
}

void printOptions(const VioNodeOptions& n, std::ostream& os) {
  const VioOptions& o = n.core;
  const CameraRig& c = n.camera;
  os << "[" << n.name << "] inputs " << n.camera_channel << ", " << n.state_prior_channel << ", "
     << n.registered_scan_channel << ", " << n.loop_correction_channel << "; output " << n.state_posterior_channel
     << "\n"
     << "  camera " << c.width << "x" << c.height << " f " << c.fx << "/" << c.fy << " c " << c.cx << "/" << c.cy
     << ", " << distortionModelName(c.distortion_model) << " distortion [" << c.distortion[0] << ", " << c.distortion[1]
     << ", " << c.distortion[2] << ", " << c.distortion[3] << "], time offset " << n.camera_time_offset_s
     << " s (match within " << n.time_tolerance_s << " s)\n"
     << "  map: voxel " << o.map.voxel_size << " m, radius " << o.map.radius << " m, max " << o.map.max_points
     << " points x " << o.map.max_observations << " patches, " << o.map.recent_scans << " recent scans, plane snap "
     << o.map.plane_snap_max_rms << " m RMS from " << o.map.plane_snap_min_points << " points, normals "
     << o.map.normal_max_rms << " m RMS from " << o.map.normal_min_points << " points\n"
     << "  selection: grid " << o.selection.grid_cell_px << " px, depth " << o.selection.min_depth << ".."
     << o.selection.max_depth << " m, occlusion cell " << o.selection.depth_cell_px << " px, max view angle "
     << o.selection.max_view_angle_deg << " deg\n"
     << "  photometric: " << o.photometric.pyramid_levels << " levels, noise " << o.photometric.noise_std << ", Huber "
     << o.photometric.huber_threshold << ", " << (o.photometric.affine_brightness ? "gain + offset" : "offset")
     << " per patch, min NCC " << o.photometric.min_ncc << ", map points known to " << o.photometric.point_std << " m\n"
     << "  update: " << o.update.max_iterations << " iterations per level, min " << o.update.min_patches
     << " patches, consistency gate at " << o.update.gate_probability << ", step <= " << o.update.max_step_pos
     << " m / " << o.update.max_step_rot_deg << " deg, covariance counts "
     << (o.update.covariance == CovarianceUpdate::kFull ? "all the information" : "the information beyond the prior")
     << ", reference floor x" << o.update.reference_floor << ", gyro bias updated while its 1-sigma > "
     << o.update.gyro_bias_std_to_update << " rad/s\n"
     << "  maintenance: new points on a " << o.maintenance.new_point_cell_px
     << " px grid (gradient >= " << o.maintenance.min_gradient << "), new patch after "
     << o.maintenance.refresh_angle_deg << " deg / x" << o.maintenance.refresh_distance_ratio << " distance / RMS "
     << o.maintenance.refresh_error << "\n";
  os << std::flush;
}

}  // namespace livo::vio
