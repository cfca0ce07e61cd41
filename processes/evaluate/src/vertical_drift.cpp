#include "livo/evaluate/vertical_drift.hpp"

#include <algorithm>
#include <cmath>

namespace livo::evaluate {

VerticalDrift verticalDrift(const std::vector<Pose3>& gt, const std::vector<Pose3>& est) {
  VerticalDrift v;
  const size_t n = std::min(gt.size(), est.size());
  for (size_t k = 0; k < n; ++k) {
    const double est_rise = est[k].translation().z() - est.front().translation().z();
    const double gt_rise = gt[k].translation().z() - gt.front().translation().z();
    v.error_m.push_back(est_rise - gt_rise);
    v.max_abs_m = std::max(v.max_abs_m, std::abs(v.error_m.back()));
    if (k > 0) v.path_length_m += (gt[k].translation() - gt[k - 1].translation()).norm();
  }
  if (!v.error_m.empty()) v.end_m = v.error_m.back();
  return v;
}

}  // namespace livo::evaluate
