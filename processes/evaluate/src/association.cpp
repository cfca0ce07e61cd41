#include "livo/evaluate/association.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

namespace livo::evaluate {

NearestStamp::NearestStamp(std::vector<double> stamps) : stamps_(std::move(stamps)), order_(stamps_.size()) {
  std::iota(order_.begin(), order_.end(), size_t{0});
  std::stable_sort(order_.begin(), order_.end(), [&](size_t a, size_t b) { return stamps_[a] < stamps_[b]; });
}

size_t NearestStamp::nearest(double t) const {
  // |s - t| does not decrease moving away from t on either side of the sorted order, so walking
  // outwards while the gap does not grow visits every candidate, ties included.
  const auto first_not_below =
      std::lower_bound(order_.begin(), order_.end(), t, [&](size_t i, double v) { return stamps_[i] < v; });
  const size_t split = static_cast<size_t>(first_not_below - order_.begin());
  double best_gap = std::numeric_limits<double>::infinity();
  size_t best = order_.empty() ? 0 : order_.front();
  auto consider = [&](size_t i) {
    const double gap = std::abs(stamps_[i] - t);
    if (gap > best_gap) return false;
    if (gap < best_gap || i < best) best = i;
    best_gap = gap;
    return true;
  };
  for (size_t k = split; k < order_.size(); ++k)
    if (!consider(order_[k])) break;
  for (size_t k = split; k-- > 0;)
    if (!consider(order_[k])) break;
  return best;
}

namespace {
std::vector<double> stampsOf(const Trajectory& t) {
  std::vector<double> s(t.size());
  for (size_t i = 0; i < t.size(); ++i) s[i] = t[i].stamp;
  return s;
}
}  // namespace

PosePairs associateByTime(const Trajectory& est, const Trajectory& gt, double max_dt) {
  PosePairs pairs;
  if (est.empty() || gt.empty()) return pairs;
  const bool est_is_longer = est.size() > gt.size();
  const Trajectory& query = est_is_longer ? gt : est;
  const NearestStamp other(stampsOf(est_is_longer ? est : gt));
  for (size_t q = 0; q < query.size(); ++q) {
    const size_t o = other.nearest(query[q].stamp);
    if (!(std::abs(other.stamp(o) - query[q].stamp) <= max_dt)) continue;
    pairs.est.push_back(est_is_longer ? o : q);
    pairs.gt.push_back(est_is_longer ? q : o);
  }
  return pairs;
}

PosePairs associateByIndex(const Trajectory& est, const Trajectory& gt) {
  if (est.size() != gt.size())
    throw AssociationError("cannot pair poses by index: the estimate has " + std::to_string(est.size()) +
                           " poses, the ground truth " + std::to_string(gt.size()));
  PosePairs pairs;
  pairs.by_index = true;
  pairs.est.resize(est.size());
  std::iota(pairs.est.begin(), pairs.est.end(), size_t{0});
  pairs.gt = pairs.est;
  return pairs;
}

}  // namespace livo::evaluate
