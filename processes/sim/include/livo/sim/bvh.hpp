// Bounding-volume hierarchy over the scene's bounded objects: built once by median splits,
// traversed nearest-child first with the current best hit pruning the rest.
#pragma once

#include <functional>
#include <vector>

#include "livo/sim/geometry.hpp"

namespace livo::sim {

class Bvh {
 public:
  /// Builds over items 0..n-1 with the given bounds.
  void build(const std::vector<Aabb>& item_bounds, int max_leaf_size = 2);

  /// Calls hit(item, t_max) for every item whose box the ray meets before the current t_max;
  /// `hit` returns the (possibly shrunk) t_max.
  template <class HitFn>
  double traverse(const PreparedRay& ray, double t_min, double t_max, HitFn&& hit) const {
    if (nodes_.empty()) return t_max;
    int stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[stack[--top]];
      double a = t_min, b = t_max;
      if (!node.box.clip(ray, &a, &b)) continue;
      if (node.count > 0) {
        for (int k = 0; k < node.count; ++k) t_max = hit(items_[node.first + k], t_max);
        continue;
      }
      // push the far child first so the near one is visited first
      const int l = node.first, r = node.first + 1;
      const bool left_first = ray.ray.direction[node.axis] >= 0.0;
      stack[top++] = left_first ? r : l;
      stack[top++] = left_first ? l : r;
    }
    return t_max;
  }

  /// Calls leaf(item) for every item under nodes whose box passes keep(box).
  template <class KeepFn, class LeafFn>
  void visit(KeepFn&& keep, LeafFn&& leaf) const {
    if (nodes_.empty()) return;
    int stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[stack[--top]];
      if (!keep(node.box)) continue;
      if (node.count > 0) {
        for (int k = 0; k < node.count; ++k) leaf(items_[node.first + k]);
        continue;
      }
      stack[top++] = node.first + 1;
      stack[top++] = node.first;
    }
  }

  size_t nodeCount() const { return nodes_.size(); }

 private:
  struct Node {
    Aabb box;
    int first = 0;  // leaf: first index into items_; inner: index of the left child (right = +1)
    int count = 0;  // > 0 for leaves
    int axis = 0;   // split axis of an inner node
  };
  int buildNode(std::vector<int>& items, int begin, int end, const std::vector<Aabb>& bounds, int max_leaf, int node);

  std::vector<Node> nodes_;
  std::vector<int> items_;
};

}  // namespace livo::sim
