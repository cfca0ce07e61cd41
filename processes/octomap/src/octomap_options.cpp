#include "livo/octomap/octomap_options.hpp"

#include <ostream>

namespace livo::octomap {

void printOptions(const OctomapOptions& o, std::ostream& os) {
  os << "octomap: resolution " << o.resolution << " m, range " << o.min_range << ".." << o.max_range << " m, prob_hit "
     << o.prob_hit << ", prob_miss " << o.prob_miss << ", clamping " << o.clamping_min << ".." << o.clamping_max
     << ", threshold " << o.occupancy_threshold << ", " << (o.colour ? "ColorOcTree" : "OcTree") << ", free_margin "
     << o.free_margin << " m, origin_segments " << o.origin_segments << ", rebuild_tolerance " << o.rebuild_tolerance
     << " m, keyframe_step " << o.keyframe_step << " m, tile_size " << o.tile_size << " m, tile_idle_s "
     << o.tile_idle_s << " s, rebuild_keyframes_per_scan " << o.rebuild_keyframes_per_scan << ", keyframe_spacing "
     << o.keyframe_spacing << " m\n";
}

}  // namespace livo::octomap
