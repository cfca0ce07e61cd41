#include "livo/report/trajectory_height.hpp"

#include <algorithm>
#include <cmath>
#include <deque>

namespace livo::report {

TrajectoryHeight::TrajectoryHeight(const Trajectory& trajectory, double reach_m, double cell_m, size_t max_cells) {
  std::vector<const StampedPose*> poses;
  for (const StampedPose& p : trajectory)
    if (p.pose.translation().allFinite()) poses.push_back(&p);
  if (poses.empty()) return;
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  std::vector<double> z;
  for (const StampedPose* p : poses) {
    const Vec3 t = p->pose.translation();
    xmin = std::min(xmin, t.x()), xmax = std::max(xmax, t.x());
    ymin = std::min(ymin, t.y()), ymax = std::max(ymax, t.y());
    z.push_back(t.z());
  }
  std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
  median_ = z[z.size() / 2];
  x0_ = xmin - reach_m, y0_ = ymin - reach_m;
  const double w = xmax - xmin + 2 * reach_m, h = ymax - ymin + 2 * reach_m;
  cell_ = std::max(cell_m, 1e-3);
  while ((std::floor(w / cell_) + 1) * (std::floor(h / cell_) + 1) > static_cast<double>(max_cells)) cell_ *= 1.5;
  nx_ = static_cast<int>(std::floor(w / cell_)) + 1;
  ny_ = static_cast<int>(std::floor(h / cell_)) + 1;
  const size_t n = static_cast<size_t>(nx_) * ny_;

  std::vector<double> sum(n, 0.0);
  std::vector<int> count(n, 0);
  for (const StampedPose* p : poses) {
    const Vec3 t = p->pose.translation();
    const int i = std::clamp(static_cast<int>((t.x() - x0_) / cell_), 0, nx_ - 1);
    const int j = std::clamp(static_cast<int>((t.y() - y0_) / cell_), 0, ny_ - 1);
    sum[static_cast<size_t>(j) * nx_ + i] += t.z();
    ++count[static_cast<size_t>(j) * nx_ + i];
  }
  heights_.assign(n, 0.0f);
  std::vector<bool> done(n, false);
  std::deque<size_t> wave;
  for (size_t c = 0; c < n; ++c) {
    if (count[c] == 0) continue;
    heights_[c] = static_cast<float>(sum[c] / count[c]);
    done[c] = true;
    wave.push_back(c);
  }
  while (!wave.empty()) {
    const size_t c = wave.front();
    wave.pop_front();
    const int i = static_cast<int>(c % nx_), j = static_cast<int>(c / nx_);
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        const int a = i + di, b = j + dj;
        if (a < 0 || b < 0 || a >= nx_ || b >= ny_) continue;
        const size_t d = static_cast<size_t>(b) * nx_ + a;
        if (done[d]) continue;
        done[d] = true;
        heights_[d] = heights_[c];
        wave.push_back(d);
      }
  }
  const auto [lo, hi] = std::minmax_element(heights_.begin(), heights_.end());
  min_ = *lo, max_ = *hi;
}

double TrajectoryHeight::at(double x, double y) const {
  if (heights_.empty()) return 0.0;
  if (!std::isfinite(x) || !std::isfinite(y)) return median_;
  const int i = std::clamp(static_cast<int>(std::floor((x - x0_) / cell_)), 0, nx_ - 1);
  const int j = std::clamp(static_cast<int>(std::floor((y - y0_) / cell_)), 0, ny_ - 1);
  return heights_[static_cast<size_t>(j) * nx_ + i];
}

}  // namespace livo::report
