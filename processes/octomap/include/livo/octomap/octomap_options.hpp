// Options of the OctoMap core (livo_octomap), with their defaults.
#pragma once

#include <iosfwd>

namespace livo::octomap {

struct OctomapOptions {
  double resolution = 0.1;  // m, leaf size
  double max_range = 30.0;  // m: longer rays only clear space up to here
  double min_range = 0.3;   // m: nearer points are dropped (sensor body)
  double prob_hit = 0.7;
  double prob_miss = 0.4;
  double clamping_min = 0.12;
  double clamping_max = 0.97;
  double occupancy_threshold = 0.5;
  bool colour = false;                 // ColorOcTree with colours from COLORED_CLOUD
  double free_margin = 0.2;            // m: a ray clears space only up to this far before its endpoint
                                       // (grazing rays then spare the surface they are about to hit)
  int origin_segments = 8;             // a sweep is cut into this many time slices, each cast from the
                                       // LiDAR position at its time (spinning sensors move during a sweep)
  double rebuild_tolerance = 0.05;     // m: a loop correction rebuilds the tree from the keyframes only
                                       // if it moves some keyframe point farther than this from where
                                       // the tree has it (0: after any change)
  double keyframe_step = 0.01;         // m: keyframe clouds are kept on disk for rebuilds, quantised to
                                       // int16 in these steps (0: float, lossless)
  double tile_size = 25.6;             // m: the tree is kept as cubes of this size (rounded to a power of
                                       // two voxels; subtrees of the one octree), each written to disk
                                       // when idle (0: one tile, never written out)
  double tile_idle_s = 5.0;            // s of sensor time without an update before a tile goes to disk
                                       // (0: never)
  int rebuild_keyframes_per_scan = 0;  // a rebuild casts this many keyframes per registered scan into
                                       // a second tree that replaces the map when all are cast (the
                                       // map stays usable meanwhile); 0: all at once at the correction
  double keyframe_spacing = 0.0;       // m: a keyframe within this distance of one kept for rebuilds is
                                       // not kept (its sweep is in the map all the same), so rebuilds
                                       // cost what the area costs, not the drive (0: keep every one)
};

void printOptions(const OctomapOptions& o, std::ostream& os);

}  // namespace livo::octomap
