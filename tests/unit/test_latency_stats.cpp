#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "livo/latency_stats.hpp"

TEST(LatencyStats, QuantilesWithinOnePercent) {
  livo::LatencyStats s;
  std::mt19937 rng(3);
  std::lognormal_distribution<double> d(std::log(2e-3), 0.6);
  std::vector<double> v;
  for (int i = 0; i < 20001; ++i) {
    v.push_back(d(rng));
    s.add(v.back());
  }
  std::sort(v.begin(), v.end());
  EXPECT_EQ(s.count(), 20001);
  EXPECT_NEAR(s.medianMs(), v[10000] * 1e3, 0.01 * v[10000] * 1e3);
  EXPECT_NEAR(s.p90Ms(), v[18000] * 1e3, 0.01 * v[18000] * 1e3);
  EXPECT_DOUBLE_EQ(s.maxMs(), v.back() * 1e3);
}

TEST(LatencyStats, EmptyAndDegenerate) {
  livo::LatencyStats s;
  EXPECT_EQ(s.medianMs(), 0.0);
  s.add(-1.0);
  s.add(std::nan(""));
  EXPECT_EQ(s.count(), 2);
  EXPECT_EQ(s.maxMs(), 0.0);
  EXPECT_GT(livo::peakRssMb(), 0.0);
}
