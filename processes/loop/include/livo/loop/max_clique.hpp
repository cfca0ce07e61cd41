// Maximum-clique outlier pruning (as in TEASER++/Quatro): correspondences are vertices, an edge
// joins two whose pairwise distances agree in source and target (a rigid motion preserves
// them), and the largest mutually consistent set is the maximum clique of that graph.
#pragma once

#include <cstdint>
#include <vector>

#include "livo/loop/point_types.hpp"

namespace livo::loop {

/// Undirected graph as sorted adjacency lists.
struct Graph {
  std::vector<std::vector<int>> adjacency;
  int size() const { return static_cast<int>(adjacency.size()); }
  void addEdge(int a, int b);  // keeps the lists sorted and free of repeats
};

struct MaxCliqueOptions {
  int64_t max_branches = 2000000;  // search budget; the best clique found so far when exceeded
};

/// An exact maximum clique (branch and bound in degeneracy order with a greedy-colouring bound),
/// as sorted vertex indices. `exact` (if given) is false if the budget ran out.
std::vector<int> maximumClique(const Graph& graph, const MaxCliqueOptions& options = {}, bool* exact = nullptr);

/// Consistency graph: i ~ j if | |s_i - s_j| - |t_i - t_j| | <= 2 * noise_bound.
Graph consistencyGraph(const Points& source, const Points& target, const Correspondences& matches, double noise_bound);

}  // namespace livo::loop
