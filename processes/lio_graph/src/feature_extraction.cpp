#include "livo/lio_graph/feature_extraction.hpp"

#include <algorithm>
#include <cmath>

#include "livo/voxel_downsample.hpp"

namespace livo::lio_graph {

namespace {

struct RingPoint {
  int index;   // into the cloud
  float time;  // ordering along the ring
  double range;
};

/// Marks the features of one ring (points in ring order); appends them to `out`.
void ringFeatures(const std::vector<RingPoint>& ring, const FeatureOptions& o, std::vector<int>* edges,
                  std::vector<int>* surfaces) {
  const int k = std::max(1, o.neighbours);
  const int n = static_cast<int>(ring.size());
  if (n < 2 * k + 1) return;
  std::vector<double> roughness(n, 0.0);
  std::vector<char> blocked(n, 0);  // never a feature (occlusion, parallel beam, or picked edge's neighbour)
  for (int i = k; i < n - k; ++i) {
    double diff = -2.0 * k * ring[i].range;
    for (int j = -k; j <= k; ++j)
      if (j != 0) diff += ring[i + j].range;
    roughness[i] = diff * diff;
  }
  for (int i = 0; i < k; ++i) blocked[i] = blocked[n - 1 - i] = 1;
  for (int i = k; i < n - k - 1; ++i) {
    // occlusion: a range jump between neighbours; the farther side's points are hidden behind an edge
    const double r0 = ring[i].range, r1 = ring[i + 1].range;
    if (std::abs(r1 - r0) > o.occlusion_gap) {
      if (r0 > r1)
        for (int j = std::max(0, i - k + 1); j <= i; ++j) blocked[j] = 1;
      else
        for (int j = i + 1; j <= std::min(n - 1, i + k); ++j) blocked[j] = 1;
    }
    // a surface nearly parallel to the beam: large jumps to both neighbours
    if (i > 0) {
      const double rp = ring[i - 1].range;
      if (std::abs(r0 - rp) > o.parallel_ratio * r0 && std::abs(r1 - r0) > o.parallel_ratio * r0) blocked[i] = 1;
    }
  }
  const int sectors = std::max(1, o.sectors);
  std::vector<int> order;
  for (int s = 0; s < sectors; ++s) {
    const int a = k + (n - 2 * k) * s / sectors, b = k + (n - 2 * k) * (s + 1) / sectors;
    if (b <= a) continue;
    // the edge candidates, roughest first; ties by position, so the result does not depend on the
    // sort's stability (the smoother points come after them and would end the loop below)
    order.clear();
    for (int i = a; i < b; ++i)
      if (roughness[i] > o.edge_threshold) order.push_back(i);
    std::sort(order.begin(), order.end(),
              [&](int x, int y) { return roughness[x] > roughness[y] || (roughness[x] == roughness[y] && x < y); });
    int picked = 0;
    for (int i : order) {
      if (picked >= o.max_edges_per_sector || roughness[i] <= o.edge_threshold) break;
      if (blocked[i]) continue;
      edges->push_back(ring[i].index);
      ++picked;
      for (int j = std::max(0, i - k); j <= std::min(n - 1, i + k); ++j) blocked[j] = 1;
    }
    for (int i = a; i < b; ++i)
      if (!blocked[i] && roughness[i] < o.surface_threshold) surfaces->push_back(ring[i].index);
  }
}

}  // namespace

ScanFeatures extractFeatures(const RingCloud& cloud, const FeatureOptions& o) {
  ScanFeatures out;
  const size_t n = cloud.points.size();
  const bool has_rings = cloud.ring.size() == n && cloud.time_offset.size() == n;
  std::vector<int> edges, surfaces;
  if (has_rings) {
    int max_ring = -1;
    for (int16_t r : cloud.ring) max_ring = std::max<int>(max_ring, r);
    std::vector<std::vector<RingPoint>> rings(static_cast<size_t>(max_ring + 1));
    for (size_t i = 0; i < n; ++i) {
      const Vec3& p = cloud.points[i];
      const double range = p.norm();
      if (cloud.ring[i] < 0 || !p.allFinite() || !(range >= o.min_range)) continue;
      rings[cloud.ring[i]].push_back({static_cast<int>(i), cloud.time_offset[i], range});
    }
    for (auto& ring : rings) {
      std::stable_sort(ring.begin(), ring.end(),
                       [](const RingPoint& a, const RingPoint& b) { return a.time < b.time; });
      ringFeatures(ring, o, &edges, &surfaces);
    }
  } else {
    for (size_t i = 0; i < n; ++i)
      if (cloud.points[i].allFinite() && cloud.points[i].norm() >= o.min_range) surfaces.push_back(static_cast<int>(i));
  }
  out.edges.reserve(edges.size());
  for (int i : edges) out.edges.push_back(cloud.points[i]);
  std::vector<Vec3> candidates;
  candidates.reserve(surfaces.size());
  for (int i : surfaces) candidates.push_back(cloud.points[i]);
  for (size_t i : firstPointPerVoxel(candidates, o.surface_voxel)) out.surfaces.push_back(candidates[i]);
  return out;
}

}  // namespace livo::lio_graph
