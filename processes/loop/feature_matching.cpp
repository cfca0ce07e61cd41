#include "feature_matching.hpp"

#include <algorithm>

#include "kdtree.hpp"

namespace livo::loop {

namespace {
using FeatureTree = KdTree<Fpfh, Features>;

// Indices of the non-zero features (zero = no normal / no neighbours).
std::vector<int> validIndices(const Features& f) {
  std::vector<int> out;
  for (size_t i = 0; i < f.size(); ++i)
    if (!f[i].isZero()) out.push_back(static_cast<int>(i));
  return out;
}
Features gather(const Features& f, const std::vector<int>& idx) {
  Features out;
  out.reserve(idx.size());
  for (int i : idx) out.push_back(f[i]);
  return out;
}
}  // namespace

Correspondences matchFeatures(const Features& source, const Features& target, const FeatureMatchingOptions& options) {
  const std::vector<int> si = validIndices(source), ti = validIndices(target);
  if (si.empty() || ti.empty()) return {};
  const Features sf = gather(source, si), tf = gather(target, ti);
  const FeatureTree ttree(tf);
  std::vector<int> source_to_target(sf.size());
  std::vector<float> dist(sf.size());
  for (size_t i = 0; i < sf.size(); ++i) {
    size_t j;
    float d2;
    ttree.nearest(sf[i], j, d2);
    source_to_target[i] = static_cast<int>(j);
    dist[i] = d2;
  }
  std::vector<int> target_to_source;
  if (options.mutual) {
    const FeatureTree stree(sf);
    target_to_source.assign(tf.size(), -1);
    std::vector<char> needed(tf.size(), 0);
    for (int j : source_to_target) needed[j] = 1;
    for (size_t j = 0; j < tf.size(); ++j) {
      if (!needed[j]) continue;
      size_t i;
      float d2;
      stree.nearest(tf[j], i, d2);
      target_to_source[j] = static_cast<int>(i);
    }
  }
  std::vector<std::pair<float, Correspondence>> kept;
  for (size_t i = 0; i < sf.size(); ++i) {
    const int j = source_to_target[i];
    if (options.mutual && target_to_source[j] != static_cast<int>(i)) continue;
    kept.push_back({dist[i], {si[i], ti[j]}});
  }
  if (options.max_correspondences > 0 && kept.size() > static_cast<size_t>(options.max_correspondences)) {
    std::stable_sort(kept.begin(), kept.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    kept.resize(options.max_correspondences);
  }
  Correspondences out;
  out.reserve(kept.size());
  for (const auto& k : kept) out.push_back(k.second);
  return out;
}

}  // namespace livo::loop
