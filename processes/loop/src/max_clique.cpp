#include "livo/loop/max_clique.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace livo::loop {

void Graph::addEdge(int a, int b) {
  if (a == b) return;
  auto insert = [](std::vector<int>& list, int v) {
    const auto it = std::lower_bound(list.begin(), list.end(), v);  // the end when edges come in order
    if (it == list.end() || *it != v) list.insert(it, v);
  };
  insert(adjacency[a], b);
  insert(adjacency[b], a);
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

inline int count(const Bits& b) {
  int c = 0;
  for (uint64_t w : b) c += __builtin_popcountll(w);
  return c;
}

// Branch and bound over a candidate set (Tomita & Seki's MCQ colouring bound), on the whole
// graph's adjacency bitsets: subproblems need no copies of their own.
struct SubSearch {
  explicit SubSearch(const std::vector<Bits>& adjacency) : adj(adjacency) {}
  const std::vector<Bits>& adj;
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
    Bits uncoloured = P, q(P.size());
    int k = 0;
    while (!none(uncoloured)) {
      ++k;
      q = uncoloured;
      for (int v = first(q); v >= 0; v = first(q)) {
        clear(uncoloured, v);
        clear(q, v);
        for (size_t w = 0; w < q.size(); ++w) q[w] &= ~adj[v][w];
        order.push_back(v);
        colour.push_back(k);
      }
    }
    Bits next(P.size());
    for (int i = static_cast<int>(order.size()) - 1; i >= 0; --i) {
      if (current.size() + colour[i] <= best.size()) return;
      const int v = order[i];
      current.push_back(v);
      for (size_t w = 0; w < next.size(); ++w) next[w] = P[w] & adj[v][w];
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

// A large clique found greedily, to start branch and bound with a tight bound: from each of the
// few vertices of the largest cores, repeatedly add the candidate of the largest core that is
// adjacent to everything chosen so far. (Only a bound: the search after it is exact.)
std::vector<int> greedyClique(const Graph& graph, const std::vector<int>& order, const std::vector<int>& core) {
  constexpr int kStarts = 8;
  const int n = graph.size();
  std::vector<int> best{order.back()};
  std::vector<int> cand, next;
  for (int oi = n - 1; oi >= std::max(0, n - kStarts); --oi) {
    const int v = order[oi];
    if (core[v] + 1 <= static_cast<int>(best.size())) continue;
    std::vector<int> clique{v};
    cand.clear();
    for (int u : graph.adjacency[v])
      if (core[u] + 1 > static_cast<int>(best.size())) cand.push_back(u);  // adjacency lists are sorted
    while (!cand.empty()) {
      if (clique.size() + cand.size() <= best.size()) break;
      const int u = *std::max_element(cand.begin(), cand.end(), [&](int a, int b) { return core[a] < core[b]; });
      clique.push_back(u);
      next.clear();
      std::set_intersection(cand.begin(), cand.end(), graph.adjacency[u].begin(), graph.adjacency[u].end(),
                            std::back_inserter(next));
      cand.swap(next);
    }
    if (clique.size() > best.size()) best = clique;
  }
  return best;
}

// A degeneracy order (repeatedly removing a vertex of minimum remaining degree) and each vertex's
// core number.
struct Degeneracy {
  std::vector<int> order;  // the vertices, in the order removed
  std::vector<int> core;   // per vertex
};

Degeneracy degeneracyOrder(const Graph& graph) {
  const int n = graph.size();
  // bucket queue by remaining degree
  std::vector<int> degree(n);
  Degeneracy out;
  out.core.resize(n);
  int max_degree = 0;
  for (int v = 0; v < n; ++v)
    max_degree = std::max(max_degree, degree[v] = static_cast<int>(graph.adjacency[v].size()));
  std::vector<std::vector<int>> buckets(max_degree + 1);
  for (int v = 0; v < n; ++v) buckets[degree[v]].push_back(v);
  std::vector<char> removed(n, 0);
  out.order.reserve(n);
  int current_core = 0;
  for (int d = 0; static_cast<int>(out.order.size()) < n;) {
    if (buckets[d].empty()) {
      ++d;
      continue;
    }
    const int v = buckets[d].back();
    buckets[d].pop_back();
    if (removed[v] || degree[v] != d) continue;
    removed[v] = 1;
    current_core = std::max(current_core, d);
    out.core[v] = current_core;
    out.order.push_back(v);
    for (int u : graph.adjacency[v]) {
      if (removed[u]) continue;
      buckets[--degree[u]].push_back(u);
      if (degree[u] < d) d = degree[u];
    }
  }
  return out;
}

// The adjacency lists as one bitset per vertex.
std::vector<Bits> adjacencyBits(const Graph& graph) {
  const int n = graph.size();
  std::vector<Bits> adj(n, Bits((n + 63) / 64, 0));
  for (int v = 0; v < n; ++v)
    for (int u : graph.adjacency[v]) set(adj[v], u);
  return adj;
}

// The vertices whose core could still beat a clique of `size`.
Bits eligibleVertices(const std::vector<int>& core, size_t size) {
  Bits eligible((core.size() + 63) / 64, 0);
  for (int u = 0; u < static_cast<int>(core.size()); ++u) {
    if (core[u] + 1 > static_cast<int>(size))
      set(eligible, u);
    else
      clear(eligible, u);
  }
  return eligible;
}

struct CliqueSearch {
  std::vector<int> clique;
  bool exact = true;  // false: the branch budget ran out
};

// The exact search, started from the clique `best`: from each vertex, the cliques among its
// neighbours after it in degeneracy order (a clique is found from its vertex that comes first).
CliqueSearch branchAndBound(const std::vector<Bits>& adj, const Degeneracy& degeneracy, std::vector<int> best,
                            int64_t max_branches) {
  const std::vector<int>& order = degeneracy.order;
  const std::vector<int>& core = degeneracy.core;
  const int n = static_cast<int>(order.size());
  const size_t words = (n + 63) / 64;
  Bits later(words, 0);     // vertices after v in degeneracy order (visited before it below)
  Bits eligible(words, 0);  // vertices whose core could still beat the best
  size_t eligible_for = 0;
  SubSearch s(adj);
  int64_t branches = 0;
  // Vertices with the largest cores hold the largest cliques: visit them first to raise the bound.
  for (int oi = n - 1; oi >= 0; --oi) {
    const int v = order[oi];
    if (core[v] + 1 > static_cast<int>(best.size())) {
      if (eligible_for != best.size()) {
        eligible_for = best.size();
        eligible = eligibleVertices(core, best.size());
      }
      Bits P(words);
      for (size_t w = 0; w < words; ++w) P[w] = adj[v][w] & later[w] & eligible[w];
      if (count(P) + 1 > static_cast<int>(best.size())) {
        s.current.clear();
        s.best.assign(best.size() - 1, -1);  // must beat best.size() including v
        s.branches = 0;
        s.budget = max_branches - branches;
        s.expand(P);
        branches += s.branches;
        if (s.best.size() + 1 > best.size() && std::find(s.best.begin(), s.best.end(), -1) == s.best.end()) {
          best.clear();
          best.push_back(v);
          best.insert(best.end(), s.best.begin(), s.best.end());
        }
        if (s.out_of_budget) return {best, false};
      }
    }
    set(later, v);
  }
  return {best, true};
}

}  // namespace

std::vector<int> maximumClique(const Graph& graph, const MaxCliqueOptions& options, bool* exact) {
  if (exact) *exact = true;
  if (graph.size() == 0) return {};
  const Degeneracy degeneracy = degeneracyOrder(graph);
  CliqueSearch search = branchAndBound(adjacencyBits(graph), degeneracy,
                                       greedyClique(graph, degeneracy.order, degeneracy.core), options.max_branches);
  if (exact) *exact = search.exact;
  std::sort(search.clique.begin(), search.clique.end());
  return search.clique;
}

Graph consistencyGraph(const Points& source, const Points& target, const Correspondences& matches, double noise_bound) {
  Graph g;
  const int n = static_cast<int>(matches.size());
  g.adjacency.resize(n);
  Points s(n), t(n);  // the matched points in order, for sequential access
  for (int i = 0; i < n; ++i) {
    s[i] = source[matches[i].source];
    t[i] = target[matches[i].target];
  }
  // | |s_i - s_j| - |t_i - t_j| | <= bound, as a + c - 2 sqrt(a c) <= bound^2 with a, c the squares.
  const double bound2 = 4.0 * noise_bound * noise_bound;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const double a = (s[j] - s[i]).squaredNorm(), c = (t[j] - t[i]).squaredNorm();
      if (a + c - 2.0 * std::sqrt(a * c) <= bound2) g.addEdge(i, j);
    }
  return g;
}

}  // namespace livo::loop
