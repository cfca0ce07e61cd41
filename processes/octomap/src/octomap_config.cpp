#include "livo/octomap/octomap_config.hpp"

#include <ostream>

namespace livo::octomap {

OctomapNodeOptions readOctomapNodeOptions(const Config& root) {
  const Config c = root.optionalSection("octomap");
  OctomapNodeOptions n;
  OctomapOptions& o = n.core;
  if (!c.isNull()) {
    c.readOptional("resolution", o.resolution);
    c.readOptional("max_range", o.max_range);
    c.readOptional("min_range", o.min_range);
    c.readOptional("prob_hit", o.prob_hit);
    c.readOptional("prob_miss", o.prob_miss);
    c.readOptional("clamping_min", o.clamping_min);
    c.readOptional("clamping_max", o.clamping_max);
    c.readOptional("occupancy_threshold", o.occupancy_threshold);
    c.readOptional("colour", o.colour);
    c.readOptional("origin_segments", o.origin_segments);
    c.readOptional("free_margin", o.free_margin);
    c.readOptional("rebuild_tolerance", o.rebuild_tolerance);
    c.readOptional("keyframe_step", o.keyframe_step);
    c.readOptional("tile_size", o.tile_size);
    c.readOptional("tile_idle_s", o.tile_idle_s);
    c.readOptional("rebuild_keyframes_per_scan", o.rebuild_keyframes_per_scan);
    c.readOptional("keyframe_spacing", o.keyframe_spacing);
    const Config ch = c.optionalSection("channels");
    ch.readOptional("registered_scan", n.registered_scan_channel);
    ch.readOptional("colored_cloud", n.colored_cloud_channel);
    ch.readOptional("keyframe", n.keyframe_channel);
    ch.readOptional("loop_correction", n.loop_correction_channel);
    ch.readOptional("octomap", n.octomap_channel);
    c.readOptional("publish_period_s", n.publish_period_s);
    c.readOptional("write_period_s", n.write_period_s);
    c.readOptional("map_name", n.map_name);
    c.checkAllUsed();
  }
  auto fail = [&](const std::string& key, const std::string& what) { throw ConfigError(c.where(key) + ": " + what); };
  if (!(o.resolution >= 0.005 && o.resolution <= 10.0)) fail("resolution", "must be in [0.005, 10] m");
  if (!(o.max_range > o.min_range && o.min_range >= 0.0)) fail("max_range", "need 0 <= min_range < max_range");
  if (!(o.prob_hit > 0.5 && o.prob_hit < 1.0)) fail("prob_hit", "must be in (0.5, 1)");
  if (!(o.prob_miss > 0.0 && o.prob_miss < 0.5)) fail("prob_miss", "must be in (0, 0.5)");
  if (!(o.clamping_min > 0.0 && o.clamping_min < o.clamping_max && o.clamping_max < 1.0))
    fail("clamping_max", "need 0 < clamping_min < clamping_max < 1");
  if (!(o.occupancy_threshold > 0.0 && o.occupancy_threshold < 1.0)) fail("occupancy_threshold", "must be in (0, 1)");
  if (!(o.free_margin >= 0.0 && o.free_margin < o.max_range)) fail("free_margin", "must be in [0, max_range)");
  if (o.origin_segments < 1) fail("origin_segments", "must be >= 1");
  if (!(o.rebuild_tolerance >= 0.0)) fail("rebuild_tolerance", "must be >= 0");
  if (!(o.keyframe_step >= 0.0 && o.keyframe_step <= 0.1)) fail("keyframe_step", "must be in [0, 0.1] m");
  if (!(o.tile_size == 0.0 || o.tile_size >= 2.0 * o.resolution))
    fail("tile_size", "must be 0 (one tile) or >= 2 voxels");
  if (!(o.tile_idle_s >= 0.0)) fail("tile_idle_s", "must be >= 0");
  if (o.rebuild_keyframes_per_scan < 0) fail("rebuild_keyframes_per_scan", "must be >= 0");
  if (!(o.keyframe_spacing >= 0.0)) fail("keyframe_spacing", "must be >= 0");
  if (n.publish_period_s < 0.0) fail("publish_period_s", "must be >= 0");
  if (n.write_period_s < 0.0) fail("write_period_s", "must be >= 0");
  if (n.map_name.empty() || n.map_name.find('/') != std::string::npos) fail("map_name", "must be a plain file name");
  return n;
}

void printOptions(const OctomapNodeOptions& o, std::ostream& os) {
  os << "octomap: inputs " << o.registered_scan_channel << ", " << o.keyframe_channel << ", "
     << o.loop_correction_channel << (o.core.colour ? ", " + o.colored_cloud_channel : std::string()) << "; output "
     << o.octomap_channel << " every " << o.publish_period_s << " s; files " << o.map_name << ".bt/.ot every "
     << o.write_period_s << " s\n";
  printOptions(o.core, os);
}

}  // namespace livo::octomap
