#include "livo/vio/vio_config.hpp"

#include <ostream>
#include <stdexcept>

namespace livo::vio {

namespace {

void readVio(const Config& c, VioNodeOptions* n) {
  VioOptions& o = n->vio;
  c.readOptional("name", n->name);
  const Config ch = c.optionalSection("channels");
  ch.readOptional("camera", n->camera_channel);
  ch.readOptional("imu", n->imu_channel);
  ch.readOptional("state_prior", n->state_prior_channel);
  ch.readOptional("state_posterior", n->state_posterior_channel);
  ch.readOptional("registered_scan", n->registered_scan_channel);
  ch.readOptional("loop_correction", n->loop_correction_channel);
  ch.readOptional("camera_free_state", n->camera_free_state_channel);
  c.readOptional("time_tolerance_s", n->time_tolerance_s);
  c.readOptional("image_buffer_s", n->image_buffer_s);
  c.readOptional("max_buffered_images", n->max_buffered_images);

  const Config img = c.optionalSection("image");
  img.readOptional("dark_level", n->image_check.dark_level);
  img.readOptional("bright_level", n->image_check.bright_level);
  img.readOptional("max_dark_fraction", n->image_check.max_dark_fraction);
  img.readOptional("max_bright_fraction", n->image_check.max_bright_fraction);

  const Config map = c.optionalSection("map");
  map.readOptional("voxel_size", o.map.voxel_size);
  map.readOptional("radius", o.map.radius);
  map.readOptional("max_points", o.map.max_points);
  map.readOptional("max_observations", o.map.max_observations);
  map.readOptional("recent_scans", o.map.recent_scans);
  map.readOptional("plane_snap_max_rms", o.map.plane_snap_max_rms);
  map.readOptional("plane_snap_min_points", o.map.plane_snap_min_points);

  const Config sel = c.optionalSection("selection");
  sel.readOptional("grid_cell_px", o.selection.grid_cell_px);
  sel.readOptional("min_depth", o.selection.min_depth);
  sel.readOptional("max_depth", o.selection.max_depth);
  sel.readOptional("depth_cell_px", o.selection.depth_cell_px);
  sel.readOptional("occlusion_tolerance", o.selection.occlusion_tolerance);
  sel.readOptional("occlusion_tolerance_rel", o.selection.occlusion_tolerance_rel);
  sel.readOptional("max_view_angle_deg", o.selection.max_view_angle_deg);
  sel.readOptional("depth_edge_radius_px", o.selection.depth_edge_radius_px);
  sel.readOptional("depth_edge_tolerance", o.selection.depth_edge_tolerance);
  sel.readOptional("depth_edge_tolerance_rel", o.selection.depth_edge_tolerance_rel);
  sel.readOptional("view_angle_weight", o.selection.view_angle_weight);
  sel.readOptional("error_weight", o.selection.error_weight);
  sel.readOptional("age_weight", o.selection.age_weight);

  const Config ph = c.optionalSection("photometric");
  ph.readOptional("pyramid_levels", o.photometric.pyramid_levels);
  ph.readOptional("noise_std", o.photometric.noise_std);
  ph.readOptional("huber_threshold", o.photometric.huber_threshold);
  ph.readOptional("affine_brightness", o.photometric.affine_brightness);
  ph.readOptional("min_gain", o.photometric.min_gain);
  ph.readOptional("max_gain", o.photometric.max_gain);
  ph.readOptional("min_ncc", o.photometric.min_ncc);

  const Config up = c.optionalSection("update");
  up.readOptional("max_iterations", o.update.max_iterations);
  up.readOptional("convergence_rot", o.update.convergence_rot);
  up.readOptional("convergence_pos", o.update.convergence_pos);
  up.readOptional("min_patches", o.update.min_patches);
  up.readOptional("max_mahalanobis", o.update.max_mahalanobis);
  up.readOptional("max_step_pos", o.update.max_step_pos);
  up.readOptional("max_step_rot_deg", o.update.max_step_rot_deg);
  up.readOptional("calibration_rotation_std_deg", o.update.calibration_rotation_std_deg);
  up.readOptional("reference_floor", o.update.reference_floor);
  up.readOptional("gyro_bias_std_to_update", o.update.gyro_bias_std_to_update);
  if (up.has("covariance")) {
    const std::string c = up.get<std::string>("covariance");
    if (c == "full")
      o.update.covariance = CovarianceUpdate::kFull;
    else if (c == "beyond_prior")
      o.update.covariance = CovarianceUpdate::kBeyondPrior;
    else
      throw ConfigError(up.where("covariance") + ": '" + c + "' is neither full nor beyond_prior");
  }

  const Config np = c.optionalSection("new_points");
  np.readOptional("cell_px", o.maintenance.new_point_cell_px);
  np.readOptional("min_gradient", o.maintenance.min_gradient);
  np.readOptional("max_per_image", o.maintenance.max_new_points);

  const Config rf = c.optionalSection("refresh");
  rf.readOptional("angle_deg", o.maintenance.refresh_angle_deg);
  rf.readOptional("distance_ratio", o.maintenance.refresh_distance_ratio);
  rf.readOptional("error", o.maintenance.refresh_error);
  rf.readOptional("min_ncc", o.maintenance.outlier_ncc);

  const Config cal = c.optionalSection("calibration");
  cal.readOptional("camera_rotation_std_deg", o.calibration.camera_rotation_std_deg);
  cal.readOptional("camera_rotation_walk_deg", o.calibration.camera_rotation_walk_deg);
  cal.readOptional("camera_translation_std", o.calibration.camera_translation_std);
  cal.readOptional("camera_translation_walk", o.calibration.camera_translation_walk);
  cal.readOptional("time_offset_std", o.calibration.time_offset_std);
  cal.readOptional("time_offset_walk", o.calibration.time_offset_walk);

  const Config rc = c.optionalSection("rotation_calibration");
  RotationCalibrationOptions& r = o.rotation_calibration;
  rc.readOptional("enabled", r.enabled);
  rc.readOptional("adopt", r.adopt);
  if (rc.has("against")) {
    const std::string a = rc.get<std::string>("against");
    if (a == "camera_free")
      r.against = RotationCalibrationOptions::Against::kCameraFree;
    else if (a == "filter")
      r.against = RotationCalibrationOptions::Against::kFilter;
    else
      throw ConfigError(rc.where("against") + ": '" + a + "' is neither camera_free nor filter");
  }
  rc.readOptional("max_corners", r.max_corners);
  rc.readOptional("min_corner_distance_px", r.min_corner_distance_px);
  rc.readOptional("corner_quality", r.corner_quality);
  rc.readOptional("klt_window_px", r.klt_window_px);
  rc.readOptional("klt_levels", r.klt_levels);
  rc.readOptional("max_track_error_px", r.max_track_error_px);
  rc.readOptional("min_baseline", r.min_baseline);
  rc.readOptional("max_pair_time", r.max_pair_time);
  rc.readOptional("min_tracks", r.min_tracks);
  rc.readOptional("ransac_threshold_px", r.ransac_threshold_px);
  rc.readOptional("cauchy_px", r.cauchy_px);
  rc.readOptional("window_pairs", r.window_pairs);
  rc.readOptional("min_pairs", r.min_pairs);
  rc.readOptional("apply_std_deg", r.apply_std_deg);
  rc.readOptional("overlay_file", r.overlay_file);
  rc.readOptional("reapply_deg", r.reapply_deg);

  auto require = [&](bool ok, const std::string& key, const char* what) {
    if (!ok) throw ConfigError(c.where(key) + ": " + what);
  };
  require(n->time_tolerance_s >= 0.0, "time_tolerance_s", "must be >= 0");
  require(n->image_buffer_s > 0.0, "image_buffer_s", "must be > 0");
  require(n->max_buffered_images >= 1, "max_buffered_images", "must be >= 1");
  require(n->image_check.max_dark_fraction > 0.0 && n->image_check.max_dark_fraction <= 1.0 &&
              n->image_check.max_bright_fraction > 0.0 && n->image_check.max_bright_fraction <= 1.0,
          "image", "fractions must be in (0, 1]");
  require(n->image_check.dark_level < n->image_check.bright_level, "image", "dark_level must be below bright_level");
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
  n.imu_channel = sensor_rig.channels.imu;
  const Config vio = root.optionalSection("vio");
  if (!vio.isNull()) {
    readVio(vio, &n);
    vio.checkAllUsed();
  }
  try {
    validate(n.vio);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(root.file() + ": vio." + e.what());
  }
  return n;
}

void printOptions(const VioNodeOptions& n, std::ostream& os) {
  const VioOptions& o = n.vio;
  const CameraRig& c = n.camera;
  os << "[" << n.name << "] inputs " << n.camera_channel << ", " << n.state_prior_channel << ", "
     << n.registered_scan_channel << ", " << n.loop_correction_channel << "; output " << n.state_posterior_channel << "\n"
     << "  camera " << c.width << "x" << c.height << " f " << c.fx << "/" << c.fy << " c " << c.cx << "/" << c.cy
     << ", " << distortionModelName(c.distortion_model) << " distortion [" << c.distortion[0] << ", " << c.distortion[1]
     << ", " << c.distortion[2] << ", " << c.distortion[3] << "], time offset " << n.camera_time_offset_s << " s (match within " << n.time_tolerance_s
     << " s)\n"
     << "  map: voxel " << o.map.voxel_size << " m, radius " << o.map.radius << " m, max " << o.map.max_points
     << " points x " << o.map.max_observations << " patches, " << o.map.recent_scans << " recent scans, plane snap "
     << o.map.plane_snap_max_rms << " m RMS from " << o.map.plane_snap_min_points << " points\n"
     << "  selection: grid " << o.selection.grid_cell_px << " px, depth " << o.selection.min_depth << ".."
     << o.selection.max_depth << " m, occlusion cell " << o.selection.depth_cell_px << " px, max view angle "
     << o.selection.max_view_angle_deg << " deg\n"
     << "  photometric: " << o.photometric.pyramid_levels << " levels, noise " << o.photometric.noise_std
     << ", Huber " << o.photometric.huber_threshold << ", "
     << (o.photometric.affine_brightness ? "gain + offset" : "offset") << " per patch, min NCC "
     << o.photometric.min_ncc << "\n"
     << "  update: " << o.update.max_iterations << " iterations per level, min " << o.update.min_patches
     << " patches, Mahalanobis^2 <= " << o.update.max_mahalanobis << ", step <= " << o.update.max_step_pos << " m / "
     << o.update.max_step_rot_deg << " deg, covariance counts "
     << (o.update.covariance == CovarianceUpdate::kFull ? "all the information" : "the information beyond the prior")
     << ", calibration floor " << o.update.calibration_rotation_std_deg << " deg x baseline, gyro bias updated while its 1-sigma > "
     << o.update.gyro_bias_std_to_update << " rad/s\n"
     << "  maintenance: new points on a " << o.maintenance.new_point_cell_px << " px grid (gradient >= "
     << o.maintenance.min_gradient << "), new patch after " << o.maintenance.refresh_angle_deg << " deg / x"
     << o.maintenance.refresh_distance_ratio << " distance / RMS " << o.maintenance.refresh_error << "\n";
  const CalibrationOptions& cal = o.calibration;
  if (cal.any())
    os << "  online calibration (1-sigma, walk per sqrt(s)): rotation " << cal.camera_rotation_std_deg << " deg ("
       << cal.camera_rotation_walk_deg << "), translation " << cal.camera_translation_std << " m ("
       << cal.camera_translation_walk << "), time offset " << cal.time_offset_std << " s (" << cal.time_offset_walk
       << ")\n";
  const RotationCalibrationOptions& rc = o.rotation_calibration;
  if (rc.enabled)
    os << "  camera rotation from image pairs: " << rc.max_corners << " KLT corners, pairs " << rc.min_baseline
       << " m apart, used once every axis is known to " << rc.apply_std_deg << " deg (" << rc.min_pairs << ".."
       << rc.window_pairs << " pairs)\n";
  os << std::flush;
}

}  // namespace livo::vio
