#include "livo/sim/bvh.hpp"

#include <algorithm>

namespace livo::sim {

void Bvh::build(const std::vector<Aabb>& bounds, int max_leaf_size) {
  nodes_.clear();
  items_.resize(bounds.size());
  for (size_t i = 0; i < bounds.size(); ++i) items_[i] = static_cast<int>(i);
  if (bounds.empty()) return;
  nodes_.reserve(2 * bounds.size());
  nodes_.emplace_back();
  buildNode(items_, 0, static_cast<int>(items_.size()), bounds, std::max(1, max_leaf_size), 0);
}

int Bvh::buildNode(std::vector<int>& items, int begin, int end, const std::vector<Aabb>& bounds, int max_leaf,
                   int node) {
  Aabb box, centers;
  for (int i = begin; i < end; ++i) {
    box.extend(bounds[items[i]]);
    centers.extend(bounds[items[i]].center());
  }
  nodes_[node].box = box;
  if (end - begin <= max_leaf) {
    nodes_[node].first = begin;
    nodes_[node].count = end - begin;
    return node;
  }
  int axis = 0;
  const Vec3 extent = centers.max - centers.min;
  if (extent.y() > extent[axis]) axis = 1;
  if (extent.z() > extent[axis]) axis = 2;
  const int mid = (begin + end) / 2;
  // stable tie-break on the item index keeps the build deterministic
  std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end, [&](int a, int b) {
    const double ca = bounds[a].center()[axis], cb = bounds[b].center()[axis];
    return ca < cb || (ca == cb && a < b);
  });
  const int left = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  nodes_.emplace_back();
  nodes_[node].first = left;
  nodes_[node].count = 0;
  nodes_[node].axis = axis;
  buildNode(items, begin, mid, bounds, max_leaf, left);
  buildNode(items, mid, end, bounds, max_leaf, left + 1);
  return node;
}

}  // namespace livo::sim
