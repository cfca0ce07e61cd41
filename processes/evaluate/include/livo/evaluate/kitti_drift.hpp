// The KITTI odometry benchmark's drift metric (Geiger et al., CVPR 2012, and its devkit):
// segments of the ground-truth path of fixed lengths, started every `step` poses; for each, the
// error of the estimate's relative pose over the segment, translation as a fraction of the segment
// length and rotation per metre, averaged over every segment of every length.
#pragma once

#include <cstddef>
#include <vector>

#include "livo/so3.hpp"

namespace livo::evaluate {

struct KittiDriftOptions {
  std::vector<double> segment_lengths = {100, 200, 300, 400, 500, 600, 700, 800};  // metres
  int step = 10;  // first poses of segments are 0, step, 2 step, ... (the devkit's 10 frames)
};

struct SegmentLengthDrift {
  double length_m = 0.0;
  size_t segments = 0;
  double translation_percent = 0.0;  // mean over the segments of 100 * |t_err| / length
  double rotation_deg_per_m = 0.0;   // mean over the segments of angle(R_err) / length
};

struct KittiDrift {
  size_t segments = 0;         // 0: the path is shorter than the shortest segment
  double path_length_m = 0.0;  // ground-truth path over the associated poses
  double translation_percent = 0.0;
  double rotation_deg_per_m = 0.0;
  std::vector<SegmentLengthDrift> per_length;  // one per segment length, in the order given
};

/// `gt` and `est` are associated pose lists of the same length. For first pose i (a multiple of
/// `step`) and length L, the segment ends at the first pose j whose ground-truth path distance from
/// pose 0 exceeds that of pose i by more than L (no segment if there is none). The error pose is
/// (P_i^-1 P_j)^-1 (Q_i^-1 Q_j) (P estimate, Q ground truth); its translation norm divided by L
/// and its rotation angle (acos((trace - 1) / 2), clamped) divided by L are averaged.
KittiDrift kittiDrift(const std::vector<Pose3>& gt, const std::vector<Pose3>& est, const KittiDriftOptions& options);

}  // namespace livo::evaluate
