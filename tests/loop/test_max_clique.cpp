#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "livo/loop/max_clique.hpp"

namespace livo::loop {
namespace {

bool isClique(const Graph& g, const std::vector<int>& c) {
  for (size_t i = 0; i < c.size(); ++i)
    for (size_t j = i + 1; j < c.size(); ++j) {
      const auto& adj = g.adjacency[c[i]];
      if (std::find(adj.begin(), adj.end(), c[j]) == adj.end()) return false;
    }
  return true;
}

Graph randomGraph(int n, double p, std::mt19937& rng) {
  Graph g;
  g.adjacency.resize(n);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      if (u(rng) < p) g.addEdge(i, j);
  return g;
}

// Exhaustive maximum clique size over all subsets (n <= 16).
size_t bruteForceCliqueSize(const Graph& g) {
  const int n = g.size();
  size_t best = 0;
  for (uint32_t mask = 1; mask < (1u << n); ++mask) {
    std::vector<int> c;
    for (int i = 0; i < n; ++i)
      if (mask >> i & 1) c.push_back(i);
    if (c.size() > best && isClique(g, c)) best = c.size();
  }
  return best;
}

TEST(MaxClique, MatchesBruteForceOnSmallRandomGraphs) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 40; ++trial) {
    const Graph g = randomGraph(14, 0.2 + 0.6 * (trial % 5) / 4.0, rng);
    bool exact = false;
    const std::vector<int> c = maximumClique(g, {}, &exact);
    EXPECT_TRUE(exact);
    EXPECT_TRUE(isClique(g, c));
    EXPECT_EQ(c.size(), bruteForceCliqueSize(g)) << "trial " << trial;
  }
}

TEST(MaxClique, FindsPlantedCliqueAmongSparseOutliers) {
  std::mt19937 rng(3);
  Graph g = randomGraph(600, 0.05, rng);
  std::vector<int> planted;
  for (int i = 0; i < 600; i += 23) planted.push_back(i);  // 27 vertices
  for (size_t i = 0; i < planted.size(); ++i)
    for (size_t j = i + 1; j < planted.size(); ++j) {
      auto& adj = g.adjacency[planted[i]];
      if (std::find(adj.begin(), adj.end(), planted[j]) == adj.end()) g.addEdge(planted[i], planted[j]);
    }
  bool exact = false;
  const std::vector<int> c = maximumClique(g, {}, &exact);
  EXPECT_TRUE(exact);
  EXPECT_EQ(c, planted);
}

TEST(MaxClique, EmptyAndEdgelessGraphs) {
  EXPECT_TRUE(maximumClique(Graph{}).empty());
  Graph g;
  g.adjacency.resize(5);
  EXPECT_EQ(maximumClique(g).size(), 1u);
}

TEST(MaxClique, ConsistencyGraphKeepsRigidInliers) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-10, 10);
  Points src, dst;
  Correspondences m;
  const Pose3 T = Pose3(Eigen::AngleAxisd(0.7, Vec3::UnitZ())) * Eigen::Translation3d(1, 2, 0.5);
  for (int i = 0; i < 100; ++i) {
    src.push_back(Vec3(u(rng), u(rng), u(rng)));
    dst.push_back(i < 30 ? Vec3(T * src.back()) : Vec3(u(rng), u(rng), u(rng)));
    m.push_back({i, i});
  }
  const std::vector<int> c = maximumClique(consistencyGraph(src, dst, m, 0.05));
  std::vector<int> expected(30);
  for (int i = 0; i < 30; ++i) expected[i] = i;
  EXPECT_EQ(c, expected);
}

}  // namespace
}  // namespace livo::loop
