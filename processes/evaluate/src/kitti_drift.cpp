#include "livo/evaluate/kitti_drift.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace livo::evaluate {

namespace {
double devkitRotationError(const Mat3& R) {
  const double d = 0.5 * (R(0, 0) + R(1, 1) + R(2, 2) - 1.0);
  return std::acos(std::max(std::min(d, 1.0), -1.0));
}
}  // namespace

KittiDrift kittiDrift(const std::vector<Pose3>& gt, const std::vector<Pose3>& est, const KittiDriftOptions& options) {
  if (gt.size() != est.size()) throw std::invalid_argument("kittiDrift: pose lists differ in length");
  if (options.step < 1) throw std::invalid_argument("kittiDrift: step must be at least 1 pose");
  for (double L : options.segment_lengths)
    if (!(L > 0.0)) throw std::invalid_argument("kittiDrift: segment lengths must be positive");

  std::vector<double> distance(gt.size(), 0.0);  // ground-truth path length from pose 0
  for (size_t i = 1; i < gt.size(); ++i)
    distance[i] = distance[i - 1] + (gt[i].translation() - gt[i - 1].translation()).norm();

  KittiDrift drift;
  drift.path_length_m = distance.empty() ? 0.0 : distance.back();
  drift.per_length.resize(options.segment_lengths.size());
  double t_sum = 0.0, r_sum = 0.0;
  std::vector<double> t_len(options.segment_lengths.size(), 0.0), r_len(options.segment_lengths.size(), 0.0);
  for (size_t first = 0; first < gt.size(); first += static_cast<size_t>(options.step)) {
    for (size_t l = 0; l < options.segment_lengths.size(); ++l) {
      const double L = options.segment_lengths[l];
      const double target = distance[first] + L;
      // First pose whose distance exceeds the target (distance is non-decreasing).
      const auto it = std::upper_bound(distance.begin() + static_cast<std::ptrdiff_t>(first), distance.end(), target);
      if (it == distance.end()) continue;
      const size_t last = static_cast<size_t>(it - distance.begin());
      const Pose3 gt_delta = gt[first].inverse() * gt[last];
      const Pose3 est_delta = est[first].inverse() * est[last];
      const Pose3 error = est_delta.inverse() * gt_delta;
      const double t_err = error.translation().norm() / L;
      const double r_err = devkitRotationError(error.linear()) / L;
      t_sum += t_err;
      r_sum += r_err;
      t_len[l] += t_err;
      r_len[l] += r_err;
      ++drift.per_length[l].segments;
      ++drift.segments;
    }
  }
  constexpr double kDeg = 180.0 / M_PI;
  for (size_t l = 0; l < options.segment_lengths.size(); ++l) {
    SegmentLengthDrift& d = drift.per_length[l];
    d.length_m = options.segment_lengths[l];
    if (d.segments == 0) continue;
    d.translation_percent = 100.0 * t_len[l] / static_cast<double>(d.segments);
    d.rotation_deg_per_m = kDeg * r_len[l] / static_cast<double>(d.segments);
  }
  if (drift.segments > 0) {
    drift.translation_percent = 100.0 * t_sum / static_cast<double>(drift.segments);
    drift.rotation_deg_per_m = kDeg * r_sum / static_cast<double>(drift.segments);
  }
  return drift;
}

}  // namespace livo::evaluate
