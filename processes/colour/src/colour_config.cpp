#include "livo/colour/colour_config.hpp"

#include <ostream>

namespace livo::colour {

ColourNodeOptions readColourNodeOptions(const Config& root) {
  const Config c = root.optionalSection("colour");
  ColourNodeOptions n;
  ColourOptions& o = n.core;
  if (!c.isNull()) {
    c.readOptional("voxel_size", o.voxel_size);
    c.readOptional("tile_size", o.tile_size);
    c.readOptional("tile_idle_s", o.tile_idle_s);
    c.readOptional("max_resident_points", o.max_resident_points);
    c.readOptional("map_margin", o.map_margin);
    c.readOptional("map_only_in_view", o.map_only_in_view);
    c.readOptional("view_margin_deg", o.view_margin_deg);
    c.readOptional("max_time_difference", o.max_time_difference);
    c.readOptional("max_depth", o.max_depth);
    c.readOptional("min_depth", o.min_depth);
    c.readOptional("border_px", o.border_px);
    c.readOptional("max_pending_images", o.max_pending_images);
    c.readOptional("depth_cell_px", o.depth_cell_px);
    c.readOptional("occluder_radius", o.occluder_radius);
    c.readOptional("max_splat_cells", o.max_splat_cells);
    c.readOptional("depth_tolerance", o.depth_tolerance);
    c.readOptional("depth_tolerance_rel", o.depth_tolerance_rel);
    c.readOptional("vignetting", o.vignetting);
    c.readOptional("use_exposure_time", o.use_exposure_time);
    c.readOptional("reference_exposure_s", o.reference_exposure_s);
    c.readOptional("estimate_gain", o.estimate_gain);
    c.readOptional("gain_min_pairs", o.gain_min_pairs);
    c.readOptional("gain_min", o.gain_min);
    c.readOptional("gain_max", o.gain_max);
    c.readOptional("outlier_threshold", o.outlier_threshold);
    c.readOptional("outlier_min_count", o.outlier_min_count);
    c.readOptional("max_count", o.max_count);
    const Config ch = c.optionalSection("channels");
    ch.readOptional("registered_scan", n.registered_scan_channel);
    ch.readOptional("odometry", n.odometry_channel);
    ch.readOptional("camera", n.camera_channel);
    ch.readOptional("keyframe", n.keyframe_channel);
    ch.readOptional("loop_correction", n.loop_correction_channel);
    ch.readOptional("colored_cloud", n.colored_cloud_channel);
    ch.readOptional("colour_save", n.colour_save_channel);
    c.readOptional("map_name", n.map_name);
    c.readOptional("max_points_per_message", n.max_points_per_message);
    c.checkAllUsed();
  }
  auto fail = [&](const std::string& key, const std::string& what) { throw ConfigError(c.where(key) + ": " + what); };
  if (!(o.voxel_size > 0.0)) fail("voxel_size", "must be > 0");
  if (!(o.tile_size >= o.voxel_size && o.tile_size <= 1000.0)) fail("tile_size", "must be in [voxel_size, 1000] m");
  if (!(o.tile_idle_s >= 0.0)) fail("tile_idle_s", "must be >= 0");
  if (o.max_resident_points < 0) fail("max_resident_points", "must be >= 0 (0: no limit)");
  if (!(o.map_margin >= 0.0)) fail("map_margin", "must be >= 0");
  if (!(o.view_margin_deg >= 0.0 && o.view_margin_deg <= 180.0)) fail("view_margin_deg", "must be in [0, 180]");
  if (!(o.max_time_difference >= 0.0)) fail("max_time_difference", "must be >= 0");
  if (!(o.min_depth > 0.0 && o.max_depth > o.min_depth)) fail("max_depth", "need 0 < min_depth < max_depth");
  if (o.depth_cell_px < 1) fail("depth_cell_px", "must be >= 1");
  if (o.max_pending_images < 1) fail("max_pending_images", "must be >= 1");
  if (o.occluder_radius < 0.0) fail("occluder_radius", "must be >= 0");
  if (!(o.vignetting >= 0.0 && o.vignetting < 1.0)) fail("vignetting", "must be in [0, 1)");
  if (!(o.gain_min > 0.0 && o.gain_max > o.gain_min)) fail("gain_max", "need 0 < gain_min < gain_max");
  if (o.max_count < 1) fail("max_count", "must be >= 1");
  if (n.max_points_per_message < 1) fail("max_points_per_message", "must be >= 1");
  if (n.map_name.empty() || n.map_name.find('/') != std::string::npos) fail("map_name", "must be a plain file name");
  return n;
}

SensorRig readColourRig(const Config& root) {
  const Config rig = root.section("rig");
  SensorRig r = readSensorRig(rig);
  if (!r.camera) throw ConfigError(rig.where("camera") + ": livo-colour needs a camera in the rig");
  return r;
}

void printOptions(const ColourNodeOptions& o, std::ostream& os) {
  os << "colour: inputs " << o.registered_scan_channel << ", " << o.odometry_channel << ", "
     << (o.camera_channel.empty() ? std::string("the rig's camera channel") : o.camera_channel) << ", "
     << o.keyframe_channel << ", " << o.loop_correction_channel << ", " << o.colour_save_channel << "; output "
     << o.colored_cloud_channel << " (at most " << o.max_points_per_message << " points a message); files "
     << o.map_name << ".ply/.pcd\n";
  printOptions(o.core, os);
}

}  // namespace livo::colour
