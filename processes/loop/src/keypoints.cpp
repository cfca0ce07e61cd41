#include "livo/loop/keypoints.hpp"

#include <algorithm>

namespace livo::loop {

std::vector<int> issKeypoints(const Points& points, const std::vector<Neighbourhood>& geometry, const PointTree& tree,
                              const IssOptions& options, const std::vector<char>& eligible) {
  const size_t n = points.size();
  std::vector<double> saliency(n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    const Neighbourhood& g = geometry[i];
    const Vec3& e = g.eigenvalues;  // ascending: e[2] = lambda1
    if (g.count < options.min_neighbours || e[2] <= 0.0 || e[1] <= 0.0) continue;
    if (e[1] / e[2] >= options.gamma21 || e[0] / e[1] >= options.gamma32) continue;
    if (e[0] < options.min_variation * e.sum()) continue;
    saliency[i] = e[0];
  }
  std::vector<int> keys;
  std::vector<std::pair<size_t, double>> nb;
  for (size_t i = 0; i < n; ++i) {
    if (saliency[i] <= 0.0 || (!eligible.empty() && !eligible[i])) continue;
    tree.radius(points[i], options.nms_radius, nb, false);
    const bool is_max = std::none_of(nb.begin(), nb.end(), [&](const auto& p) {
      return saliency[p.first] > saliency[i] || (saliency[p.first] == saliency[i] && p.first < i);
    });
    if (is_max) keys.push_back(static_cast<int>(i));
  }
  std::stable_sort(keys.begin(), keys.end(), [&](int a, int b) { return saliency[a] > saliency[b]; });
  return keys;
}

}  // namespace livo::loop
