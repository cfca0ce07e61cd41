// The 3D view in report.html: the RGB map (thinned on a voxel grid so the page stays small) and
// the trajectory, drawn by three.js (WebGL) with orbit controls, a height cut and a point size.
// The points travel in the page as base64 of little-endian float32 positions and uint8 colours.
#pragma once

#include <string>
#include <vector>

#include "livo/coloured_point_files.hpp"
#include "livo/trajectory_io.hpp"

namespace livo::report {

struct ViewerOptions {
  size_t max_points = 1'000'000;  // more points in the map: thinned on a voxel grid to at most this
  double point_size_m = 0.05;     // the map's point spacing (livo-colour's voxel_size)
  double cut_above_m = 1.0;       // the height cut starts this far above the trajectory's median height
};

struct ViewerScene {
  Vec3 origin = Vec3::Zero();         // subtracted from every position (float32 keeps mm only near it)
  std::vector<float> positions;       // x y z of each point, relative to origin
  std::vector<uint8_t> colours;       // r g b of each point
  size_t map_points = 0;              // in the map file
  double voxel_m = 0.0;               // the thinning grid (0: every point)
  double point_size_m = 0.05;         // of the points drawn (the grid when thinned)
  std::vector<float> path;            // x y z of the trajectory's positions, relative to origin
  std::vector<uint32_t> path_pieces;  // positions per piece (pathPieces: split at resets and gaps)
  Vec3 camera = Vec3::Zero();         // the start view (obliqueView), relative to origin; the page
  Vec3 target = Vec3::Zero();         // keeps its direction and moves it to fit the box in the canvas
  Vec3 box_min = Vec3::Zero();        // what the start view frames (relative to origin)
  Vec3 box_max = Vec3::Zero();
  double fov_deg = 50.0;            // vertical
  double z_min = 0.0, z_max = 0.0;  // height range of the points and the path, relative to origin
  double cut_z = 0.0;               // the height cut at start, relative to origin
  size_t size() const { return colours.size() / 3; }
};

/// Keeps the first point of each voxel of the finest grid point_size_m x 1.25^k (k >= 0) that
/// leaves at most max_points, or every point when there are no more than that (deterministic:
/// the file's order decides), and the trajectory's positions at least 5 cm apart (at most 50,000).
ViewerScene viewerScene(const ColouredPoints& map, const Trajectory& trajectory,
                        const std::vector<double>& reset_stamps, const ViewerOptions& options = {});

/// The page's 3D section: the scene's data blocks, a canvas with its controls and the script
/// that draws them. Needs THREE and THREE.OrbitControls loaded before it runs (html_report.hpp
/// inlines them); reports what it drew, or why it could not, in #viewer-status.
std::string viewerSection(const ViewerScene& scene, const std::string& description);

}  // namespace livo::report
