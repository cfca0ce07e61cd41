// Vertical drift of an estimate against ground truth: the height error after anchoring both at the
// first pair by their heights alone, at the end, per 100 m of ground-truth path, and its largest
// magnitude over the run. World z must be up (against gravity) in both worlds.
//
// Only the height is anchored (a yaw and a translation at the first pose, the 4-DoF anchor), not the
// first pose's full attitude as the end-point drift anchors it: a rigid anchor would turn the first
// pose's roll or pitch error into a height error growing with distance (0.3 deg over 200 m: 1.05 m),
// and would take out a tilt of the estimate's world, which is a height error of its map.
#pragma once

#include <vector>

#include "livo/so3.hpp"

namespace livo::evaluate {

struct VerticalDrift {
  std::vector<double> error_m;  // per pair: (z_est,k - z_est,0) - (z_gt,k - z_gt,0)
  double end_m = 0.0;           // error at the last pair (signed)
  double max_abs_m = 0.0;       // largest |error| over the pairs
  double path_length_m = 0.0;   // ground-truth path from the first to the last pair
  bool hasPath() const { return path_length_m > 0.0; }
  /// end_m per 100 m of ground-truth path (signed); 0 without a path (check hasPath).
  double per100m() const { return hasPath() ? end_m / (path_length_m / 100.0) : 0.0; }
};

/// `gt` and `est` are the associated pose lists (same length).
VerticalDrift verticalDrift(const std::vector<Pose3>& gt, const std::vector<Pose3>& est);

}  // namespace livo::evaluate
