#include "livo/vio/vio_options.hpp"

#include <stdexcept>

namespace livo::vio {

void validate(const VioOptions& o) {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(what);
  };
  require(o.map.voxel_size > 0.0, "map.voxel_size must be > 0");
  require(o.map.radius > 0.0, "map.radius must be > 0");
  require(o.map.max_points >= 1, "map.max_points must be >= 1");
  require(o.map.max_observations >= 1, "map.max_observations must be >= 1");
  require(o.map.recent_scans >= 1, "map.recent_scans must be >= 1");
  require(o.map.plane_snap_max_rms >= 0.0, "map.plane_snap_max_rms must be >= 0");
  require(o.map.plane_snap_min_points >= 3, "map.plane_snap_min_points must be >= 3");
  require(o.map.normal_max_rms >= 0.0, "map.normal_max_rms must be >= 0");
  require(o.map.normal_min_points >= 3, "map.normal_min_points must be >= 3");
  require(o.selection.grid_cell_px >= 8, "selection.grid_cell_px must be >= 8");
  require(o.selection.min_depth > 0.0 && o.selection.max_depth > o.selection.min_depth,
          "selection: need 0 < min_depth < max_depth");
  require(o.selection.depth_cell_px >= 1, "selection.depth_cell_px must be >= 1");
  require(o.selection.occlusion_tolerance >= 0.0 && o.selection.occlusion_tolerance_rel >= 0.0,
          "selection: occlusion tolerances must be >= 0");
  require(o.selection.depth_edge_radius_px >= 0.0 && o.selection.depth_edge_tolerance >= 0.0 &&
              o.selection.depth_edge_tolerance_rel >= 0.0,
          "selection: depth edge radius and tolerances must be >= 0");
  require(o.selection.max_view_angle_deg > 0.0 && o.selection.max_view_angle_deg < 90.0,
          "selection.max_view_angle_deg must be in (0, 90)");
  require(o.photometric.pyramid_levels >= 1 && o.photometric.pyramid_levels <= 4,
          "photometric.pyramid_levels must be in 1..4");
  require(o.photometric.noise_std > 0.0, "photometric.noise_std must be > 0");
  require(o.photometric.huber_threshold > 0.0, "photometric.huber_threshold must be > 0");
  require(o.photometric.min_gain > 0.0 && o.photometric.max_gain >= o.photometric.min_gain,
          "photometric: need 0 < min_gain <= max_gain");
  require(o.photometric.point_std >= 0.0 && o.photometric.point_std <= 1.0, "photometric.point_std must be in [0, 1]");
  require(o.photometric.min_ncc >= -1.0 && o.photometric.min_ncc < 1.0, "photometric.min_ncc must be in [-1, 1)");
  require(o.update.max_iterations >= 1, "update.max_iterations must be >= 1");
  require(o.update.min_patches >= 1, "update.min_patches must be >= 1");
  require(o.update.calibration_information_scale > 0.0 && o.update.calibration_information_scale <= 1.0,
          "update.calibration_information_scale must be in (0, 1]");
  require(o.update.gate_probability > 0.0 && o.update.gate_probability < 1.0,
          "update.gate_probability must be in (0, 1)");
  require(o.update.max_step_pos > 0.0 && o.update.max_step_rot_deg > 0.0, "update: step bounds must be > 0");
  require(o.update.reference_floor >= 0.0, "update.reference_floor must be >= 0");
  require(o.update.gyro_bias_std_to_update >= 0.0, "update.gyro_bias_std_to_update must be >= 0");
  require(o.maintenance.new_point_cell_px >= 8, "new_points.cell_px must be >= 8");
  require(o.maintenance.max_new_points >= 0, "new_points.max_per_image must be >= 0");
  require(o.maintenance.refresh_angle_deg > 0.0 && o.maintenance.refresh_distance_ratio >= 1.0,
          "refresh: need angle_deg > 0 and distance_ratio >= 1");
}

}  // namespace livo::vio
