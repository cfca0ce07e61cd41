// report.html: report.md as one self-contained page (styles, pictures and scripts inlined, nothing
// fetched from a network) with the RGB map and the trajectory in 3D (map_viewer.hpp). three.js
// comes from Debian's libjs-three, read when the page is made; without it the page is written all
// the same, with a note where the 3D view would be.
#pragma once

#include <string>
#include <vector>

#include "livo/report/map_viewer.hpp"

namespace livo::report {

struct HtmlOptions {
  std::string three_dir = "/usr/share/javascript/three";  // three.min.js, examples/js/controls/OrbitControls.js
  std::string colour_map = "colour_map.ply";              // relative to the run's folder unless absolute
  ViewerOptions viewer;
};

struct HtmlReport {
  std::string html;
  bool viewer = false;                // the page has the 3D view (a map or a trajectory to show, three.js there)
  bool three_missing = false;         // a 3D view was due but three.js is not there: a note in its place
  std::vector<std::string> warnings;  // what else is missing from the page (a picture, the map), one line each
  size_t points_shown = 0;
  size_t map_points = 0;
  double voxel_m = 0.0;
};

/// A file as a data: URI (its type from its extension: png, jpg, jpeg, gif, svg, webp); empty if
/// it cannot be read or its type is not one of these.
std::string dataUri(const std::string& path);

/// The page for the run's folder: its report.md (throws std::runtime_error if that is missing),
/// the pictures it shows inlined, and the 3D view of colour_map.ply and trajectory.tum (or
/// odometry.tum) when the folder has either.
HtmlReport reportHtml(const std::string& dir, const HtmlOptions& options = {});

}  // namespace livo::report
