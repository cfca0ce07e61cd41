#include "livo/lio_graph/lio_graph_config.hpp"

#include <ostream>

#include "livo/sensor_rig.hpp"
#include "livo/text_format.hpp"

namespace livo::lio_graph {

namespace {

/// What the rig decides: the sensors' channels, the IMU's noise and gravity, the LiDAR's extrinsic
/// and range limits, the wheels.
LioGraphNodeOptions fromRig(const SensorRig& rig, const Config& root) {
  LioGraphNodeOptions n;
  LioGraphOptions& o = n.core;
  n.imu_channel = rig.channels.imu;
  n.lidar_channel = rig.channels.lidar;
  n.wheel_channel = rig.channels.wheel;
  o.imu_noise = ImuPreintegrationNoise::fromRig(rig.imu);
  o.gravity = rig.imu.gravity;
  if (!rig.lidar) throw ConfigError(root.where("rig") + ": livo-lio-graph needs a rig.lidar");
  o.extrinsics.T_I_L = rig.lidar->T_I_L;
  o.imu_noise.systematic_error_window_s = 1.0 / rig.lidar->rate_hz;  // the states are the sweeps
  o.min_range = std::max(rig.lidar->min_range, o.features.min_range);
  o.max_range = rig.lidar->max_range;
  if (rig.wheel) {
    o.use_wheel = true;
    o.wheel_rig = *rig.wheel;
    o.wheel_noise = WheelPreintegrationNoise::fromRig(*rig.wheel);
  }
  return n;
}

/// lio_graph.channels.
void readChannels(const Config& ch, LioGraphNodeOptions* n) {
  ch.readOptional("odometry", n->odometry_channel);
  ch.readOptional("registered_scan", n->registered_scan_channel);
  ch.readOptional("keyframe", n->keyframe_channel);
  ch.readOptional("loop_correction", n->loop_correction_channel);
  ch.readOptional("visual_state", n->visual_state_channel);
}

/// The visual subsystem's keys (visual_*).
void readVisualKeys(const Config& c, LioGraphNodeOptions* n) {
  LioGraphOptions& o = n->core;
  c.readOptional("visual_state", o.use_visual_motion);
  c.readOptional("visual_max_wait_s", n->visual_max_wait_s);
  c.readOptional("visual_factor", o.visual_factor);
  c.readOptional("visual_sigma_rotation_deg", o.visual_sigma_rotation_deg);
  c.readOptional("visual_sigma_translation", o.visual_sigma_translation);
  c.readOptional("visual_sigma_translation_ratio", o.visual_sigma_translation_ratio);
  c.readOptional("visual_cauchy", o.visual_cauchy);
  c.readOptional("visual_scale_std", o.visual_scale_std);
}

/// The wheels' keys (wheel*): `wheel: false` turns a rig's wheels off, never on without them.
void readWheelKeys(const Config& c, bool rig_has_wheel, LioGraphNodeOptions* n) {
  LioGraphOptions& o = n->core;
  bool wheel = o.use_wheel;
  if (c.readOptional("wheel", wheel)) o.use_wheel = wheel && rig_has_wheel;
  c.readOptional("wheel_cauchy", o.wheel_cauchy);
  c.readOptional("wheel_scale_std", o.wheel_scale_std);
  c.readOptional("wheel_max_wait_s", n->wheel_max_wait_s);
}

/// The window's, the keyframes' and the local map's keys.
void readWindowKeys(const Config& c, LioGraphOptions* o) {
  c.readOptional("window_states", o->window_states);
  c.readOptional("solver_iterations", o->solver_iterations);
  c.readOptional("keyframe_distance", o->keyframe.min_distance);
  c.readOptional("keyframe_angle_deg", o->keyframe.min_angle_deg);
  c.readOptional("local_map_keyframes", o->local_map_keyframes);
  c.readOptional("local_map_radius", o->local_map_radius);
  c.readOptional("local_map_spacing", o->local_map_spacing);
  int max_stored = static_cast<int>(o->max_stored_keyframes);
  if (c.readOptional("max_stored_keyframes", max_stored)) {
    if (max_stored < 1) throw ConfigError(c.where("max_stored_keyframes") + ": must be >= 1");
    o->max_stored_keyframes = static_cast<size_t>(max_stored);
  }
  c.readOptional("map_edge_voxel", o->map_edge_voxel);
  c.readOptional("map_surface_voxel", o->map_surface_voxel);
}

/// The LiDAR factor's, the features' and the scan matching's keys.
void readMatchingKeys(const Config& c, LioGraphOptions* o) {
  c.readOptional("lidar_point_sigma", o->lidar_point_sigma);
  c.readOptional("lidar_information_scale", o->lidar_information_scale);
  c.readOptional("edge_threshold", o->features.edge_threshold);
  c.readOptional("surface_threshold", o->features.surface_threshold);
  c.readOptional("surface_voxel", o->features.surface_voxel);
  c.readOptional("degenerate_eigenvalue", o->matching.degenerate_eigenvalue);
  c.readOptional("max_neighbour_distance", o->matching.max_neighbour_distance);
  c.readOptional("max_plane_distance", o->matching.max_plane_distance);
  c.readOptional("min_planarity", o->matching.min_planarity);
}

/// The planar factors' and the plane extraction's keys.
void readPlaneKeys(const Config& c, LioGraphOptions* o) {
  c.readOptional("planar_factors", o->planar_factors);
  c.readOptional("planar_ground_only", o->planar_ground_only);
  c.readOptional("plane_sigma_angle_deg", o->plane_sigma_angle_deg);
  c.readOptional("plane_sigma_distance", o->plane_sigma_distance);
  c.readOptional("plane_match_angle_deg", o->plane_match_angle_deg);
  c.readOptional("plane_match_distance", o->plane_match_distance);
  c.readOptional("plane_threshold_base", o->planes.threshold_base);
  c.readOptional("plane_threshold_per_metre", o->planes.threshold_per_metre);
  c.readOptional("plane_max_quality_ratio", o->planes.max_quality_ratio);
}

/// Out-of-range values are errors naming their key in the section `c`.
void checkRanges(const LioGraphNodeOptions& n, const Config& c) {
  const LioGraphOptions& o = n.core;
  auto fail = [&](const std::string& key, const std::string& what) { throw ConfigError(c.where(key) + ": " + what); };
  if (o.window_states < 2) fail("window_states", "must be >= 2");
  if (o.solver_iterations < 1) fail("solver_iterations", "must be >= 1");
  if (!(o.keyframe.min_distance > 0.0)) fail("keyframe_distance", "must be > 0");
  if (!(o.keyframe.min_angle_deg > 0.0)) fail("keyframe_angle_deg", "must be > 0");
  if (o.local_map_keyframes < 1) fail("local_map_keyframes", "must be >= 1");
  if (!(o.local_map_radius > 0.0)) fail("local_map_radius", "must be > 0");
  if (!(o.local_map_spacing >= 0.0)) fail("local_map_spacing", "must be >= 0 (0: the newest keyframes only)");
  if (!(o.matching.max_neighbour_distance > 0.0)) fail("max_neighbour_distance", "must be > 0");
  if (!(o.matching.max_plane_distance > 0.0)) fail("max_plane_distance", "must be > 0");
  if (!(o.matching.min_planarity >= 0.0 && o.matching.min_planarity < 1.0)) fail("min_planarity", "must be in [0, 1)");
  if (!(o.map_edge_voxel > 0.0)) fail("map_edge_voxel", "must be > 0");
  if (!(o.map_surface_voxel > 0.0)) fail("map_surface_voxel", "must be > 0");
  if (!(o.features.surface_voxel > 0.0)) fail("surface_voxel", "must be > 0");
  if (!(o.lidar_point_sigma > 0.0)) fail("lidar_point_sigma", "must be > 0");
  if (!(o.lidar_information_scale > 0.0)) fail("lidar_information_scale", "must be > 0");
  if (!(o.wheel_cauchy > 0.0)) fail("wheel_cauchy", "must be > 0");
  if (!(o.wheel_scale_std >= 0.0 && o.wheel_scale_std <= 0.2)) fail("wheel_scale_std", "must be in [0, 0.2]");
  if (!(o.plane_sigma_angle_deg > 0.0)) fail("plane_sigma_angle_deg", "must be > 0");
  if (!(o.plane_sigma_distance > 0.0)) fail("plane_sigma_distance", "must be > 0");
  if (!(o.plane_match_angle_deg > 0.0)) fail("plane_match_angle_deg", "must be > 0");
  if (!(o.plane_match_distance > 0.0)) fail("plane_match_distance", "must be > 0");
  if (!(o.planes.threshold_base > 0.0)) fail("plane_threshold_base", "must be > 0");
  if (!(o.planes.threshold_per_metre >= 0.0)) fail("plane_threshold_per_metre", "must be >= 0");
  if (!(o.planes.max_quality_ratio > 0.0)) fail("plane_max_quality_ratio", "must be > 0");
  if (!(n.wheel_max_wait_s >= 0.0)) fail("wheel_max_wait_s", "must be >= 0");
  if (!(n.visual_max_wait_s >= 0.0)) fail("visual_max_wait_s", "must be >= 0");
  if (!(o.visual_sigma_rotation_deg > 0.0)) fail("visual_sigma_rotation_deg", "must be > 0");
  if (!(o.visual_sigma_translation > 0.0)) fail("visual_sigma_translation", "must be > 0");
  if (!(o.visual_sigma_translation_ratio >= 0.0)) fail("visual_sigma_translation_ratio", "must be >= 0");
  if (!(o.visual_cauchy > 0.0)) fail("visual_cauchy", "must be > 0");
  if (!(o.visual_scale_std >= 0.0 && o.visual_scale_std <= 0.2)) fail("visual_scale_std", "must be in [0, 0.2]");
}

}  // namespace

LioGraphNodeOptions readLioGraphNodeOptions(const Config& root) {
  const SensorRig rig = readSensorRig(root.section("rig"));
  LioGraphNodeOptions n = fromRig(rig, root);
  const Config c = root.optionalSection("lio_graph");
  if (!c.isNull()) {
    c.readOptional("name", n.name);
    readChannels(c.optionalSection("channels"), &n);
    readVisualKeys(c, &n);
    readWheelKeys(c, rig.wheel.has_value(), &n);
    readWindowKeys(c, &n.core);
    readMatchingKeys(c, &n.core);
    readPlaneKeys(c, &n.core);
    c.checkAllUsed();
  }
  checkRanges(n, c);
  return n;
}

void printOptions(const LioGraphNodeOptions& n, std::ostream& os) {
  const LioGraphOptions& o = n.core;
  os << "[" << n.name << "] inputs " << n.imu_channel << ", " << n.lidar_channel
     << (o.use_wheel ? ", " + n.wheel_channel : std::string())
     << (o.use_visual_motion ? ", " + n.visual_state_channel : std::string()) << ", " << n.loop_correction_channel
     << "; outputs " << n.odometry_channel << ", " << n.registered_scan_channel << ", " << n.keyframe_channel << "\n"
     << "  window " << o.window_states << " sweeps, " << o.solver_iterations << " solver iterations; factors: IMU "
     << "preintegration, bias walk, LiDAR pose (sigma " << o.lidar_point_sigma << " m x scale "
     << o.lidar_information_scale << ")"
     << (o.use_wheel ? ", " + wheelFactorText(o.wheel_rig, o.wheel_scale_std) : std::string())
     << (o.planar_factors ? (o.planar_ground_only ? ", adaptive planar factors (the ground)"
                                                  : ", adaptive planar factors (every plane)")
                          : "")
     << (o.use_visual_motion ? "; deskew and guess from the visual subsystem's motion" : "")
     << (o.use_visual_motion && o.visual_factor ? ", and its motion as a relative-pose factor" : "") << "\n"
     << "  keyframes every " << o.keyframe.min_distance << " m / " << o.keyframe.min_angle_deg
     << " deg; local map: the newest " << o.local_map_keyframes << " keyframes"
     << (o.local_map_spacing > 0.0 ? " and the oldest per " + formatSignificant(o.local_map_spacing) + " m cell" : "")
     << " within " << o.local_map_radius << " m\n";
}

}  // namespace livo::lio_graph
