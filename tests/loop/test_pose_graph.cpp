#include <cmath>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "pose_graph.hpp"
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
