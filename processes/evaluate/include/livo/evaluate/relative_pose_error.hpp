// Relative pose error over a fixed number of frames (TUM RGB-D benchmark; evo's metrics.RPE with
// delta in frames): for pose pairs (i, j = i + delta) of two associated pose lists,
// E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j) with Q the ground truth and P the estimate.
#pragma once

#include <cstddef>
#include <vector>

#include "livo/so3.hpp"

namespace livo::evaluate {

struct RelativePoseErrorOptions {
  int delta = 1;           // frames between the two poses of a pair (>= 1)
  bool all_pairs = false;  // every i (i, i + delta); otherwise i = 0, delta, 2 delta, ...
};

struct RelativePoseError {
  std::vector<size_t> from, to;       // pair indices into the associated lists
  std::vector<double> translation_m;  // |translation of E|
  std::vector<double> rotation_deg;   // rotation angle of E
};

/// `gt` and `est` are the associated pose lists (same length). Fewer than delta + 1 poses give no pairs.
RelativePoseError relativePoseError(const std::vector<Pose3>& gt, const std::vector<Pose3>& est,
                                    const RelativePoseErrorOptions& options);

/// Rotation angle in radians, in [0, pi], of a rotation matrix that may be slightly off SO(3) (as
/// KITTI pose files are): the quaternion is taken from the matrix as SciPy's
/// `Rotation.from_matrix` takes it (largest of the diagonal and the trace decides) and normalised,
/// which is what evo's `so3_log_angle` measures.
double rotationAngle(const Mat3& R);

}  // namespace livo::evaluate
