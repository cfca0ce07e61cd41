#include "max_clique.hpp"

#include <algorithm>
#include <cmath>

namespace livo::loop {

void Graph::addEdge(int a, int b) {
  if (a == b) return;
  adjacency[a].push_back(b);
  adjacency[b].push_back(a);
}

namespace {

using Bits = std::vector<uint64_t>;
inline bool test(const Bits& b, int i) { return (b[i >> 6] >> (i & 63)) & 1u; }
inline void set(Bits& b, int i) { b[i >> 6] |= uint64_t{1} << (i & 63); }
inline void clear(Bits& b, int i) { b[i >> 6] &= ~(uint64_t{1} << (i & 63)); }
inline bool none(const Bits& b) {
  for (uint64_t w : b)
    if (w) return false;
  return true;
}
inline int first(const Bits& b) {
  for (size_t w = 0; w < b.size(); ++w)
    if (b[w]) return static_cast<int>(w * 64 + __builtin_ctzll(b[w]));
  return -1;
}

// Branch and bound on a small dense subproblem (Tomita & Seki's MCQ colouring bound).
struct SubSearch {
  std::vector<Bits> adj;
  std::vector<int> current, best;
  int64_t branches = 0, budget = 0;
  bool out_of_budget = false;

  void expand(Bits P) {
    if (out_of_budget) return;
    if (++branches > budget) {
      out_of_budget = true;
      return;
    }
    // Greedy colouring of P: vertices in increasing colour order.
    std::vector<int> order, colour;
    Bits uncoloured = P;
    int k = 0;
    while (!none(uncoloured)) {
      ++k;
      Bits q = uncoloured;
      for (int v = first(q); v >= 0; v = first(q)) {
        clear(uncoloured, v);
        clear(q, v);
        for (size_t w = 0; w < q.size(); ++w) q[w] &= ~adj[v][w];
        order.push_back(v);
        colour.push_back(k);
      }
    }
    for (int i = static_cast<int>(order.size()) - 1; i >= 0; --i) {
      if (current.size() + colour[i] <= best.size()) return;
      const int v = order[i];
      current.push_back(v);
      Bits next = P;
      for (size_t w = 0; w < next.size(); ++w) next[w] &= adj[v][w];
      if (none(next)) {
        if (current.size() > best.size()) best = current;
      } else {
        expand(next);
      }
      current.pop_back();
      clear(P, v);
    }
  }
};

}  // namespace

std::vector<int> maximumClique(const Graph& graph, const MaxCliqueOptions& options, bool* exact) {
  const int n = graph.size();
  if (exact) *exact = true;
  if (n == 0) return {};
  // Degeneracy order by repeatedly removing a vertex of minimum remaining degree (bucket queue).
  std::vector<int> degree(n), core(n), position(n);
  int max_degree = 0;
  for (int v = 0; v < n; ++v) max_degree = std::max(max_degree, degree[v] = static_cast<int>(graph.adjacency[v].size()));
  std::vector<std::vector<int>> buckets(max_degree + 1);
  for (int v = 0; v < n; ++v) buckets[degree[v]].push_back(v);
  std::vector<char> removed(n, 0);
  std::vector<int> order;
  order.reserve(n);
  int current_core = 0;
  for (int d = 0; static_cast<int>(order.size()) < n;) {
    if (buckets[d].empty()) {
      ++d;
      continue;
    }
    const int v = buckets[d].back();
    buckets[d].pop_back();
    if (removed[v] || degree[v] != d) continue;
    removed[v] = 1;
    current_core = std::max(current_core, d);
    core[v] = current_core;
    position[v] = static_cast<int>(order.size());
    order.push_back(v);
    for (int u : graph.adjacency[v]) {
      if (removed[u]) continue;
      buckets[--degree[u]].push_back(u);
      if (degree[u] < d) d = degree[u];
    }
  }

  std::vector<int> best{order.back()};
  int64_t branches = 0;
  // Vertices with the largest cores hold the largest cliques: visit them first to raise the bound.
  for (int oi = n - 1; oi >= 0; --oi) {
    const int v = order[oi];
    if (core[v] + 1 <= static_cast<int>(best.size())) continue;
    std::vector<int> cand;
    for (int u : graph.adjacency[v])
      if (position[u] > position[v] && core[u] + 1 > static_cast<int>(best.size())) cand.push_back(u);
    if (static_cast<int>(cand.size()) + 1 <= static_cast<int>(best.size())) continue;
    std::sort(cand.begin(), cand.end());
    const int m = static_cast<int>(cand.size());
    const size_t words = (m + 63) / 64;
    SubSearch s;
    s.adj.assign(m, Bits(words, 0));
    for (int a = 0; a < m; ++a)
      for (int u : graph.adjacency[cand[a]]) {
        const auto it = std::lower_bound(cand.begin(), cand.end(), u);
        if (it != cand.end() && *it == u) set(s.adj[a], static_cast<int>(it - cand.begin()));
      }
    s.best.assign(best.size() - 1, -1);  // must beat best.size() including v
    s.budget = options.max_branches - branches;
    Bits all(words, 0);
    for (int a = 0; a < m; ++a) set(all, a);
    if (m > 0) s.expand(all);
    branches += s.branches;
    if (s.best.size() + 1 > best.size() && std::find(s.best.begin(), s.best.end(), -1) == s.best.end()) {
      best.clear();
      best.push_back(v);
      for (int a : s.best) best.push_back(cand[a]);
    }
    if (s.out_of_budget) {
      if (exact) *exact = false;
      break;
    }
  }
  std::sort(best.begin(), best.end());
  return best;
}

Graph consistencyGraph(const Points& source, const Points& target, const Correspondences& matches, double noise_bound) {
  Graph g;
  const int n = static_cast<int>(matches.size());
  g.adjacency.resize(n);
  const double bound = 2.0 * noise_bound;
  for (int i = 0; i < n; ++i) {
    const Vec3& si = source[matches[i].source];
    const Vec3& ti = target[matches[i].target];
    for (int j = i + 1; j < n; ++j) {
      const double ds = (source[matches[j].source] - si).norm();
      const double dt = (target[matches[j].target] - ti).norm();
      if (std::abs(ds - dt) <= bound) g.addEdge(i, j);
    }
  }
  return g;
}

}  // namespace livo::loop
