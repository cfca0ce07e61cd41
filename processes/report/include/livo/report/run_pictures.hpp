// `livo-report pictures`: the pictures of a run's maps beside its report. From the files a run
// leaves in its folder: trajectory_top.svg (the trajectory from above with its weak spots; needs
// no ground truth), map_top.png and map_oblique.png (the RGB map, colour_map.ply, from above and
// from the side), octomap_slice.png (a height band of octomap.bt from above). What cannot be drawn
// (a map the run did not make, a file that does not read) is noted, never fatal to the rest;
// pictures.json lists what was drawn and the notes, and `livo-report markdown` turns it into the
// report's "Maps" section.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "livo/report/octomap_slice.hpp"
#include "livo/report/picture_set.hpp"

namespace livo::report {

struct PictureOptions {
  std::string colour_map = "colour_map.ply";  // relative to the run's folder unless absolute
  std::string octomap = "octomap.bt";
  double cut_above_m = 1.0;    // the RGB map pictures leave out points higher above the trajectory
  SliceBand band;              // the OctoMap slice
  double point_size_m = 0.05;  // the RGB map's point spacing (livo-colour's voxel_size)
  int long_side_px = 1600;     // the top views' longer side; the oblique view's width
  double top_edl = 1.0;        // eye-dome lighting of the top view (per metre of height step)
  double oblique_edl = 1.5;    // and of the oblique view (per halving of the distance)
};

/// The picture files this command writes (all of them, drawn or not).
const std::vector<std::string>& pictureFiles();

/// Draws what the folder's files allow and writes the pictures into it; any picture file of an
/// earlier run that is not drawn again is removed. Never throws for a missing or unreadable input
/// (a note says so), nor for one picture that fails (a note says why). `progress` (if given) gets
/// a line per picture with the seconds it took.
PictureSet makePictures(const std::string& dir, const PictureOptions& options = {}, std::ostream* progress = nullptr);

}  // namespace livo::report
