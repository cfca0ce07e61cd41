// Fast Point Feature Histograms (Rusu et al. 2009), the features of the coarse stage:
// per point, a simplified histogram (SPFH) of the Darboux-frame angles to its neighbours within
// `radius`, then FPFH = SPFH(p) + mean over neighbours k of SPFH(k) / |p - k|.
#pragma once

#include "local_geometry.hpp"
#include "point_types.hpp"

namespace livo::loop {

struct FpfhOptions {
  double normal_radius = 1.0;   // m
  double feature_radius = 2.5;  // m
};

/// Features of `points` with `normals` (zero normals give zero features, which matching skips).
Features computeFpfh(const Points& points, const Points& normals, const PointTree& tree, double radius);

/// Convenience: normals and FPFH in one call, building the kd-tree.
Features computeFpfh(const Points& points, const FpfhOptions& options);

}  // namespace livo::loop
