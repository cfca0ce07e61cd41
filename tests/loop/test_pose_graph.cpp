#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include "livo/loop/pose_graph.hpp"
#include "synthetic_scenes.hpp"

namespace livo::loop {
namespace {
using namespace livo::loop::testing;

// Ground truth: a closed 40-node loop (a circle of radius 20 m with a small height wave).
std::vector<Pose3> circle(int n) {
  std::vector<Pose3> out;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    Pose3 T = yawPose(a + M_PI / 2, Vec3(20 * std::cos(a), 20 * std::sin(a), 0.5 * std::sin(3 * a)));
    out.push_back(T);
  }
  return out;
}

// Odometry with a yaw bias of `bias` rad per edge, integrated from the first pose.
std::vector<Pose3> driftedOdometry(const std::vector<Pose3>& truth, double bias) {
  std::vector<Pose3> odo{truth[0]};
  for (size_t i = 1; i < truth.size(); ++i) {
    Pose3 rel = truth[i - 1].inverse() * truth[i];
    rel.linear() = Eigen::AngleAxisd(bias, Vec3::UnitZ()).toRotationMatrix() * rel.linear();
    odo.push_back(odo.back() * rel);
  }
  return odo;
}

// With exact relative measurements, the optimum is the truth whatever the (drifted) start.
TEST(PoseGraph, ExactMeasurementsRecoverTruthFromDriftedStart) {
  const std::vector<Pose3> truth = circle(40);
  const std::vector<Pose3> start = driftedOdometry(truth, 0.01);
  PoseGraph g;
  for (int i = 0; i < 40; ++i) g.addNode(i, start[i]);
  for (int i = 1; i < 40; ++i) g.addEdge({i - 1, i, truth[i - 1].inverse() * truth[i], Mat6::Identity() * 100, false});
  g.addEdge({39, 0, truth[39].inverse() * truth[0], Mat6::Identity() * 100, true});
  EXPECT_GT(translationError(start[39], truth[39]), 3.0);
  const PoseGraphSummary s = g.optimize();
  EXPECT_LT(s.final_cost, 1e-12);
  for (int i = 0; i < 40; ++i) {
    EXPECT_LT(translationError(g.pose(i), truth[i]), 1e-5) << i;
    EXPECT_LT(rotationErrorDeg(g.pose(i), truth[i]), 1e-4) << i;
  }
}

// Two loop measurements of the same node pair, fused into one edge, give the optimum of the two
// as separate edges (to first order: they differ by 2 cm and 0.3 deg here), and the fused
// information is their sum. Loops of other pairs and odometry edges are never fused.
TEST(PoseGraph, ParallelLoopEdgesAreFusedIntoOne) {
  const std::vector<Pose3> truth = circle(40);
  const std::vector<Pose3> odo = driftedOdometry(truth, 0.01);
  Pose3 second = truth[39].inverse() * truth[0];
  second.translation() += Vec3(0.01, -0.015, 0.005);
  second.linear() = second.linear() * Eigen::AngleAxisd(0.005, Vec3(0.3, 0.2, 1.0).normalized()).toRotationMatrix();
  Mat6 first_information = Mat6::Identity() * 400, second_information = Mat6::Identity() * 100;
  second_information(0, 0) = 900;  // not a multiple of the first
  auto build = [&](bool fuse) {
    PoseGraphOptions o;
    o.fuse_parallel_loops = fuse;
    PoseGraph g(o);
    for (int i = 0; i < 40; ++i) g.addNode(i, odo[i]);
    for (int i = 1; i < 40; ++i) g.addEdge({i - 1, i, odo[i - 1].inverse() * odo[i], Mat6::Identity(), false});
    EXPECT_TRUE(g.addEdge({39, 0, truth[39].inverse() * truth[0], first_information, true}));
    g.optimize();  // the first loop's residual is in the solver's problem before the second comes
    EXPECT_EQ(g.addEdge({39, 0, second, second_information, true}), !fuse);
    EXPECT_TRUE(g.addEdge({20, 0, truth[20].inverse() * truth[0], first_information, true}));  // another pair
    g.optimize();
    return g;
  };
  const PoseGraph fused = build(true), separate = build(false);
  EXPECT_EQ(fused.edges().size(), separate.edges().size() - 1);
  EXPECT_EQ(fused.numLoops(), 2u);
  EXPECT_TRUE(fused.edges()[39].information.isApprox(first_information + second_information));
  double worst_t = 0.0, worst_r = 0.0;
  for (int i = 0; i < 40; ++i) {
    worst_t = std::max(worst_t, translationError(fused.pose(i), separate.pose(i)));
    worst_r = std::max(worst_r, rotationErrorDeg(fused.pose(i), separate.pose(i)));
  }
  EXPECT_LT(worst_t, 1e-4);
  EXPECT_LT(worst_r, 1e-3);
}

// Biased odometry plus one exact loop edge: the correction spreads the drift; the loop's end
// pose comes back close to the truth and the first node stays fixed.
TEST(PoseGraph, LoopEdgeCutsEndDrift) {
  const std::vector<Pose3> truth = circle(40);
  const std::vector<Pose3> odo = driftedOdometry(truth, 0.01);
  PoseGraph g;
  for (int i = 0; i < 40; ++i) g.addNode(i, odo[i]);
  for (int i = 1; i < 40; ++i) g.addEdge({i - 1, i, odo[i - 1].inverse() * odo[i], Mat6::Identity(), false});
  Mat6 loop_info = Mat6::Identity() * 1e4;
  g.addEdge({39, 0, truth[39].inverse() * truth[0], loop_info, true});
  const double before = translationError(odo[39], truth[39]);
  g.optimize();
  EXPECT_LT(translationError(g.pose(39), truth[39]), 0.1 * before);
  EXPECT_LT(translationError(g.pose(0), truth[0]), 1e-12);
  EXPECT_EQ(g.numLoops(), 1u);
}

// Three laps of a 120-node circle with biased, noisy odometry; from the second lap on, a loop edge to the
// first lap every 8 nodes. Solved on the node's schedule (warm-started, after every loop, new nodes
// initialised from the previous optimised pose) the final graph equals the full batch solve.
struct NoisyLaps {
  std::vector<Pose3> truth, rel;
  std::vector<PoseEdge> loops;  // by the node they close at
  Mat6 odometry_information, loop_information;
  static constexpr int kPerLap = 120;
  explicit NoisyLaps(int laps) {
    std::mt19937 rng(5);
    std::normal_distribution<double> nr(0.0, 1e-3), nt(0.0, 1e-2), lr(0.0, 2e-3), lt(0.0, 1e-2);
    const int n = laps * kPerLap;
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * i / kPerLap;
      truth.push_back(yawPose(a + M_PI / 2, Vec3(40 * std::cos(a), 40 * std::sin(a), 0.3 * std::sin(2 * a))));
    }
    rel.push_back(Pose3::Identity());
    for (int i = 1; i < n; ++i) {
      Pose3 d = truth[i - 1].inverse() * truth[i];
      d.linear() = d.linear() * so3::Exp(Vec3(nr(rng), nr(rng), 2e-3 + nr(rng)));  // and a yaw bias
      d.translation() = 1.01 * d.translation() + Vec3(nt(rng), nt(rng), nt(rng));  // and a scale error
      rel.push_back(d);
    }
    for (int i = kPerLap; i < n; i += 8) {
      const int j = i % kPerLap;
      Pose3 m = truth[j].inverse() * truth[i];
      m.linear() = m.linear() * so3::Exp(Vec3(lr(rng), lr(rng), lr(rng)));
      m.translation() += Vec3(lt(rng), lt(rng), lt(rng));
      loops.push_back({j, i, m, Mat6::Zero(), true});
    }
    Vec6 os, ls;
    os << Vec3::Constant(2e-3), Vec3::Constant(3e-2);
    ls << Vec3::Constant(2e-3), Vec3::Constant(1e-2);
    odometry_information = os.cwiseInverse().cwiseAbs2().asDiagonal();
    loop_information = ls.cwiseInverse().cwiseAbs2().asDiagonal();
    for (PoseEdge& e : loops) e.information = loop_information;
  }
  int size() const { return static_cast<int>(truth.size()); }
};

TEST(PoseGraph, WarmStartedSolvesOnTheLoopScheduleEqualTheFullSolve) {
  const NoisyLaps laps(3);
  PoseGraph incremental;
  size_t next_loop = 0;
  int solves = 0, iterations = 0;
  for (int i = 0; i < laps.size(); ++i) {
    incremental.addNode(i, i == 0 ? laps.truth[0] : Pose3(incremental.pose(i - 1) * laps.rel[i]));
    if (i > 0) incremental.addEdge({i - 1, i, laps.rel[i], laps.odometry_information, false});
    if (next_loop < laps.loops.size() && laps.loops[next_loop].to == i) {
      incremental.addEdge(laps.loops[next_loop++]);
      const PoseGraphSummary s = incremental.optimize();
      EXPECT_TRUE(s.converged) << i;
      ++solves;
      iterations += s.iterations;
    }
  }
  ASSERT_EQ(next_loop, laps.loops.size());

  PoseGraphOptions tight;
  tight.max_iterations = 200;
  tight.function_tolerance = 1e-14;
  tight.parameter_tolerance = 1e-14;
  tight.initial_trust_region_radius = 1e4;  // Ceres' default: the plain, cautious full solve
  PoseGraph full(tight);
  Pose3 odo = laps.truth[0];
  for (int i = 0; i < laps.size(); ++i) {
    if (i > 0) odo = odo * laps.rel[i];
    full.addNode(i, odo);
    if (i > 0) full.addEdge({i - 1, i, laps.rel[i], laps.odometry_information, false});
  }
  for (const PoseEdge& e : laps.loops) full.addEdge(e);
  const double odometry_drift = translationError(odo, laps.truth.back());
  const PoseGraphSummary fs = full.optimize();
  EXPECT_TRUE(fs.converged);

  double worst_t = 0.0, worst_r = 0.0, worst_truth = 0.0;
  for (int i = 0; i < laps.size(); ++i) {
    worst_t = std::max(worst_t, translationError(incremental.pose(i), full.pose(i)));
    worst_r = std::max(worst_r, rotationErrorDeg(incremental.pose(i), full.pose(i)));
    worst_truth = std::max(worst_truth, translationError(full.pose(i), laps.truth[i]));
  }
  std::printf(
      "[pose-graph] %d warm solves, %.1f iterations each; full solve %d iterations; incremental vs full: "
      "%.2e m, %.2e deg; odometry drift %.2f m, worst solved %.3f m\n",
      solves, double(iterations) / solves, fs.iterations, worst_t, worst_r, odometry_drift, worst_truth);
  EXPECT_LT(worst_t, 1e-4);
  EXPECT_LT(worst_r, 1e-4);
  EXPECT_GT(odometry_drift, 1.0);                // the loops had something to correct ...
  EXPECT_LT(worst_truth, 0.1 * odometry_drift);  // ... and did
  EXPECT_LE(double(iterations) / solves, 5.0);   // warm starts: a few steps per loop
}

// A copy keeps the nodes and edges and optimises on its own.
TEST(PoseGraph, CopiesOptimiseIndependently) {
  const std::vector<Pose3> truth = circle(40);
  const std::vector<Pose3> start = driftedOdometry(truth, 0.01);
  PoseGraph g;
  for (int i = 0; i < 40; ++i) g.addNode(i, start[i]);
  for (int i = 1; i < 40; ++i) g.addEdge({i - 1, i, start[i - 1].inverse() * start[i], Mat6::Identity() * 100, false});
  g.optimize();  // builds g's solver problem (no loop yet: nothing moves)
  PoseGraph copy = g;
  copy.addEdge({39, 0, truth[39].inverse() * truth[0], Mat6::Identity() * 100, true});
  copy.optimize();
  EXPECT_LT(translationError(copy.pose(39), truth[39]), 0.5 * translationError(start[39], truth[39]));
  EXPECT_LT(translationError(g.pose(39), start[39]), 1e-9);  // the original is untouched
  EXPECT_EQ(g.numLoops(), 0u);
  g.addEdge({39, 0, truth[39].inverse() * truth[0], Mat6::Identity() * 100, true});
  g.optimize();
  EXPECT_LT(translationError(g.pose(39), copy.pose(39)), 1e-9);
}

// A loop that asks for a pitch the odometry does not have (its measured relative pose pitched by
// 1 deg, as the loops' levelling errors are): without gravity priors the graph tilts the nodes;
// with them every node keeps the odometry's roll and pitch to within a small fraction of that,
// while the loop's yaw and translation still correct the drift.
TEST(PoseGraph, GravityPriorsKeepRollAndPitch) {
  const std::vector<Pose3> truth = circle(40);
  const std::vector<Pose3> odo = driftedOdometry(truth, 0.002);
  Pose3 loop = truth[39].inverse() * truth[0];
  loop.linear() = loop.linear() * Eigen::AngleAxisd(0.0175, Vec3::UnitY()).toRotationMatrix();
  const auto tilt = [](const Pose3& a, const Pose3& b) {  // angle between the two up axes seen in the body
    const Vec3 ua = a.linear().transpose() * Vec3::UnitZ(), ub = b.linear().transpose() * Vec3::UnitZ();
    return std::acos(std::min(1.0, ua.dot(ub)));
  };
  double worst_tilt[2] = {0.0, 0.0}, end_error[2] = {0.0, 0.0};
  for (int with_prior = 0; with_prior < 2; ++with_prior) {
    PoseGraph g;
    for (int i = 0; i < 40; ++i) {
      g.addNode(i, odo[i]);
      if (with_prior) g.addGravityPrior(i, odo[i].linear().transpose() * Vec3::UnitZ(), 1e-4);
    }
    Mat6 odo_info = Mat6::Identity();
    odo_info.topLeftCorner<3, 3>() *= 1e6;      // 1 mrad
    odo_info.bottomRightCorner<3, 3>() *= 1e4;  // 1 cm
    for (int i = 1; i < 40; ++i) g.addEdge({i - 1, i, odo[i - 1].inverse() * odo[i], odo_info, false});
    g.addEdge({39, 0, loop, Mat6::Identity() * 1e4, true});
    g.optimize();
    for (int i = 0; i < 40; ++i) worst_tilt[with_prior] = std::max(worst_tilt[with_prior], tilt(g.pose(i), odo[i]));
    end_error[with_prior] = translationError(g.pose(39), truth[39]);
  }
  const double drift = translationError(odo[39], truth[39]);
  std::printf(
      "[pose-graph] tilt from the odometry's attitude: %.3f deg without priors, %.4f deg with; end %.3f / %.3f m "
      "(odometry %.3f m)\n",
      worst_tilt[0] * 180 / M_PI, worst_tilt[1] * 180 / M_PI, end_error[0], end_error[1], drift);
  EXPECT_GT(worst_tilt[0], 0.2 * 0.0175);  // 0.28 deg: the odometry edges take part of the 1 deg
  EXPECT_LT(worst_tilt[1], 0.05 * 0.0175);
  EXPECT_LT(end_error[1], 0.5 * drift);
}

TEST(PoseGraph, GravityPriorNeedsAKnownNodeAndAPositiveSigma) {
  PoseGraph g;
  g.addNode(0, Pose3::Identity());
  EXPECT_THROW(g.addGravityPrior(1, Vec3::UnitZ(), 1e-3), std::invalid_argument);
  EXPECT_THROW(g.addGravityPrior(0, Vec3::UnitZ(), 0.0), std::invalid_argument);
  EXPECT_THROW(g.addGravityPrior(0, Vec3::Zero(), 1e-3), std::invalid_argument);
  EXPECT_NO_THROW(g.addGravityPrior(0, Vec3::UnitZ(), 1e-3));
}

TEST(PoseGraph, UnknownNodeIsRejected) {
  PoseGraph g;
  g.addNode(0, Pose3::Identity());
  EXPECT_THROW(g.addEdge({0, 5, Pose3::Identity(), Mat6::Identity(), false}), std::invalid_argument);
}

TEST(PoseGraph, RelativeInformationIsPositiveDefinite) {
  Mat6 a = Mat6::Identity() * 0.01, b = Mat6::Identity() * 0.005;  // b - a negative: clamped
  const Mat6 info = relativeInformation(a, b, 0.01, 0.05);
  Eigen::SelfAdjointEigenSolver<Mat6> es(info);
  EXPECT_GT(es.eigenvalues().minCoeff(), 0.0);
  EXPECT_NEAR(info(0, 0), 1.0 / (0.01 * 0.01), 1e-6);
}

}  // namespace
}  // namespace livo::loop
