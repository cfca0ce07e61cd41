// Pairing by time (evo's rule, ties and the gap bound) and by index.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "livo/evaluate/association.hpp"
#include "synthetic_trajectory.hpp"

using namespace livo;
using namespace livo::evaluate;

namespace {
Trajectory stamped(const std::vector<double>& stamps) {
  Trajectory t;
  for (double s : stamps) t.push_back({s, Pose3::Identity()});
  return t;
}
}  // namespace

TEST(NearestStamp, TakesTheFirstOfEquallyNearStampsLikeArgmin) {
  const NearestStamp n({3.0, 1.0, 2.0, 1.0, 0.5});
  EXPECT_EQ(n.nearest(1.0), 1u);  // stamps 1 and 3 are 1.0: the first
  EXPECT_EQ(n.nearest(1.2), 1u);
  EXPECT_EQ(n.nearest(0.75), 1u);  // 0.5 (index 4) and 1.0 (index 1) equally near: index 1 first
  EXPECT_EQ(n.nearest(-5.0), 4u);
  EXPECT_EQ(n.nearest(9.0), 0u);
  EXPECT_EQ(n.nearest(2.5), 0u);  // 2 (index 2) and 3 (index 0): index 0 first
}

TEST(NearestStamp, MatchesBruteForceArgminOnUnsortedStamps) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> coarse(0, 200);  // many exact ties
  std::vector<double> stamps(500);
  for (auto& s : stamps) s = 0.05 * coarse(rng);
  const NearestStamp n(stamps);
  std::uniform_real_distribution<double> query(-1.0, 11.0);
  for (int q = 0; q < 2000; ++q) {
    const double t = q % 3 == 0 ? 0.025 * coarse(rng) : query(rng);
    size_t best = 0;
    for (size_t i = 1; i < stamps.size(); ++i)
      if (std::abs(stamps[i] - t) < std::abs(stamps[best] - t)) best = i;
    ASSERT_EQ(n.nearest(t), best) << "t = " << t;
  }
}

TEST(Association, ShorterTrajectoryQueriesAndGapIsInclusive) {
  // Ground truth longer: each estimated pose takes its nearest ground-truth pose.
  const Trajectory gt = stamped({0.0, 0.1, 0.2, 0.3, 0.4, 0.5});
  const Trajectory est = stamped({0.005, 0.26, 0.5, 0.9});
  PosePairs p = associateByTime(est, gt, 0.01);
  ASSERT_EQ(p.size(), 2u);  // 0.26 is 0.04 from 0.3; 0.9 is far
  EXPECT_EQ(p.est, (std::vector<size_t>{0, 2}));
  EXPECT_EQ(p.gt, (std::vector<size_t>{0, 5}));
  EXPECT_FALSE(p.by_index);
  // The gap bound is inclusive (binary-exact stamps).
  p = associateByTime(stamped({0.25}), stamped({0.0, 0.5, 1.0}), 0.25);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p.gt[0], 0u);  // 0.0 and 0.5 are both 0.25 away: the first

  // Estimate longer: each ground-truth pose queries; an estimated pose may serve twice.
  const Trajectory est_long = stamped({0.0, 0.01, 0.02, 1.0, 1.01, 5.0, 6.0});
  const Trajectory gt_short = stamped({0.012, 0.013, 1.004});
  p = associateByTime(est_long, gt_short, 0.01);
  EXPECT_EQ(p.gt, (std::vector<size_t>{0, 1, 2}));
  EXPECT_EQ(p.est, (std::vector<size_t>{1, 1, 3}));

  // As many poses: the estimate queries.
  p = associateByTime(stamped({0.0, 0.104}), stamped({0.1, 0.102}), 0.01);
  EXPECT_EQ(p.est, (std::vector<size_t>{1}));
  EXPECT_EQ(p.gt, (std::vector<size_t>{1}));
}

TEST(Association, NothingAssociatesAcrossTimeBases) {
  const Trajectory gt = fixtures::wigglyTrajectory(100, 10.0, 1000.0);
  const Trajectory est = fixtures::wigglyTrajectory(100, 10.0, 0.0);
  EXPECT_TRUE(associateByTime(est, gt, 0.01).empty());
  EXPECT_TRUE(associateByTime(Trajectory{}, gt, 0.01).empty());
}

TEST(Association, ByIndexNeedsEqualLengths) {
  const Trajectory a = fixtures::straightTrajectory(5), b = fixtures::straightTrajectory(6);
  const PosePairs p = associateByIndex(a, a);
  EXPECT_TRUE(p.by_index);
  EXPECT_EQ(p.est, (std::vector<size_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(p.gt, p.est);
  try {
    associateByIndex(a, b);
    FAIL() << "lengths differ";
  } catch (const AssociationError& e) {
    EXPECT_NE(std::string(e.what()).find("5 poses"), std::string::npos) << e.what();
  }
}
