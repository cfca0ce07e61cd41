// Fast Point Feature Histograms (Rusu et al. 2009), the features of the coarse stage:
// per point, a simplified histogram (SPFH) of the Darboux-frame angles to its neighbours within
// `radius`, then FPFH = SPFH(p) + mean over neighbours k of SPFH(k) / |p - k|.
#pragma once

#include "livo/loop/local_geometry.hpp"
#include "livo/loop/point_types.hpp"

namespace livo::loop {

/// FPFH of the points `at` (indices into `points`), from the SPFH of those points and of their
/// neighbours within `radius`; SPFH is computed only where needed. Points with zero normals get
/// zero features (which matching skips) and are left out of their neighbours' histograms.
Features computeFpfh(const Points& points, const Points& normals, const PointTree& tree, double radius,
                     const std::vector<int>& at);

/// Exactly whether computeFpfh(points, normals, tree, radius, at) has a non-zero feature, for the
/// price of a radius search or two when one of the points `at` has a valid pair with a point of
/// its neighbourhood (the usual case). Only if none has are the features computed: that decides it
/// unless the kd-tree finds a pair at the radius from one end and not from the other.
bool anyNonZeroFpfh(const Points& points, const Points& normals, const PointTree& tree, double radius,
                    const std::vector<int>& at);

}  // namespace livo::loop
