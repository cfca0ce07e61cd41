// Options of the colouring core (livo_colour), with their defaults. Read from the `colour:` section
// of a project config by colour_config.hpp; the core itself never parses files.
#pragma once

#include <iosfwd>

namespace livo::colour {

struct ColourOptions {
  // Map
  double voxel_size = 0.05;           // m: one map point per voxel (the first point measured in it)
  double tile_size = 16.0;            // m: the map is kept in square tiles (x, y) ...
  double tile_idle_s = 20.0;          // ... and a tile without a new point for this long (sensor
                                      // time) goes to disk until a point falls in it again (0: never)
  int max_resident_points = 2500000;  // more points in memory than this: the least recently used
                                      // tiles go to disk sooner (none an image may still need;
                                      // 0: no limit). ~65 bytes a point with its index slot
  double map_margin = 10.0;           // m: scan points farther than max_depth + map_margin from the
                                      // body at the scan time are not put in the map: no image within
                                      // max_time_difference can colour them (body speed below
                                      // map_margin / max_time_difference, 33 m/s), and with a long-range
                                      // LiDAR they would keep every tile in reach in memory
  bool map_only_in_view = true;       // scan points outside the camera's widened view cone (below)
                                      // are not put in the map: no image of their time window sees them
  double view_margin_deg = 15.0;      // the cone: the camera's field (half-angle to the farthest
                                      // image corner) + this + the body's rotation over the window
                                      // (1.5 x the fastest rate of the last 2 s), from the camera at
                                      // the scan pose; points nearer than the camera's travel over
                                      // the window always pass, farther ones by asin(travel / range) more
  // Which images a point may take colour from
  double max_time_difference = 0.3;  // s: |t_point - t_image| at most (point = when last measured)
  double max_depth = 30.0;           // m in front of the camera
  double min_depth = 0.2;            // m
  int border_px = 2;                 // ignore pixels this close to the image border
  int max_pending_images = 50;       // images waiting for scans (no LIO output): the oldest is
                                     // dropped beyond this, so memory stays bounded
  // Occlusion test (depth buffer over the image)
  int depth_cell_px = 4;          // depth-buffer cell size in pixels
  double occluder_radius = 0.06;  // m: each point covers a disc of this radius in the buffer
  int max_splat_cells = 6;        // cap on the splat half-size in cells
  double depth_tolerance = 0.05;  // m: a point is visible if z <= nearest + tol + rel * z
  double depth_tolerance_rel = 0.02;
  // Photometry
  double vignetting = 0.0;            // radial fall-off calibration: gain 1 - v * min(1, r^2 / (half diagonal)^2)
  bool use_exposure_time = true;      // divide by the image's exposure_time (if > 0) ...
  double reference_exposure_s = 0.0;  // ... relative to this (0: the first image's exposure)
  bool estimate_gain = true;          // robust per-image gain against the map's current colours
  int gain_min_pairs = 50;            // map points with colour needed for a gain estimate
  double gain_min = 0.5, gain_max = 2.0;
  // Accumulation (robust running mean)
  double outlier_threshold = 60.0;  // grey levels: farther from the mean is rejected ...
  int outlier_min_count = 3;        // ... once the point has this many observations
  int max_count = 50;               // the running mean's weight saturates (slow drift allowed)
};

void printOptions(const ColourOptions& o, std::ostream& os);

}  // namespace livo::colour
