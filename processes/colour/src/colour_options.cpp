#include "livo/colour/colour_options.hpp"

#include <ostream>

namespace livo::colour {

void printOptions(const ColourOptions& o, std::ostream& os) {
  os << "colour: voxel_size " << o.voxel_size << " m, tiles " << o.tile_size << " m to disk after " << o.tile_idle_s
     << " s idle or beyond " << o.max_resident_points << " points in memory, points within max_depth + " << o.map_margin
     << " m of the body" << (o.map_only_in_view ? " and in the camera's view cone (+ " : " (view cone off: ")
     << o.view_margin_deg << " deg), max_time_difference " << o.max_time_difference << " s, depth " << o.min_depth
     << ".." << o.max_depth << " m, border " << o.border_px << " px, at most " << o.max_pending_images
     << " images waiting\n"
     << "  occlusion: cell " << o.depth_cell_px << " px, occluder_radius " << o.occluder_radius << " m (max "
     << o.max_splat_cells << " cells), tolerance " << o.depth_tolerance << " m + " << o.depth_tolerance_rel << " z\n"
     << "  photometry: vignetting " << o.vignetting << ", use_exposure_time " << (o.use_exposure_time ? "yes" : "no")
     << ", reference_exposure " << o.reference_exposure_s << " s, estimate_gain " << (o.estimate_gain ? "yes" : "no")
     << " (min " << o.gain_min_pairs << " pairs, " << o.gain_min << ".." << o.gain_max << ")\n"
     << "  accumulation: outlier_threshold " << o.outlier_threshold << " after " << o.outlier_min_count
     << " observations, max_count " << o.max_count << "\n";
}

}  // namespace livo::colour
