// The 4-DoF (yaw + translation) alignment's closed form against a brute-force search, and the sets
// on which it is undefined.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "livo/evaluate/four_dof_alignment.hpp"
#include "synthetic_trajectory.hpp"

using namespace livo;
using namespace livo::evaluate;

namespace {
Pose3 worldRotation(const Vec3& rotation_vector, const Vec3& translation = Vec3::Zero()) {
  Pose3 T = Pose3::Identity();
  T.linear() = so3::Exp(rotation_vector);
  T.translation() = translation;
  return T;
}

/// Sum of squared distances after the yaw `yaw` and the best translation for it (the mean offset).
double fourDofCost(const std::vector<Vec3>& x, const std::vector<Vec3>& y, double yaw) {
  const Mat3 R = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix();
  Vec3 offset = Vec3::Zero();
  for (size_t k = 0; k < x.size(); ++k) offset += y[k] - R * x[k];
  offset /= static_cast<double>(x.size());
  double cost = 0.0;
  for (size_t k = 0; k < x.size(); ++k) cost += (R * x[k] + offset - y[k]).squaredNorm();
  return cost;
}

std::vector<Vec3> positions(const Trajectory& t) {
  std::vector<Vec3> p;
  for (const auto& s : t) p.push_back(s.pose.translation());
  return p;
}
}  // namespace

// The closed form is the least-squares optimum: no yaw on a fine grid does better, on a noisy
// 3-D path with a planted yaw.
TEST(FourDofAlignment, ClosedFormYawIsTheLeastSquaresMinimum) {
  const Trajectory gt = fixtures::wigglyTrajectory(800);
  Trajectory est = fixtures::transformed(gt, worldRotation(Vec3(0, 0, -2.2), Vec3(10, 4, -1)));
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.5);
  for (auto& s : est) s.pose.translation() += Vec3(noise(rng), noise(rng), noise(rng));
  const std::vector<Vec3> x = positions(est), y = positions(gt);
  const Similarity3 fit = fourDofAlignment(x, y);
  const double best = fourDofCost(x, y, yawOf(fit.rotation));
  EXPECT_NEAR(yawOf(fit.rotation), 2.2, 0.01);
  for (int i = -2000; i <= 2000; ++i) {
    const double yaw = i * M_PI / 2000.0;
    EXPECT_GE(fourDofCost(x, y, yaw), best * (1.0 - 1e-12)) << yaw;
  }
  // The translation is the best one for that yaw (the mean offset).
  double direct = 0.0;
  for (size_t k = 0; k < x.size(); ++k) direct += (fit.apply(x[k]) - y[k]).squaredNorm();
  EXPECT_NEAR(direct, best, 1e-9 * best);
}

TEST(FourDofAlignment, UndefinedWithoutHorizontalSpread) {
  const std::vector<Vec3> vertical = {Vec3(1, 2, 0), Vec3(1, 2, 1), Vec3(1, 2, 3)};
  EXPECT_THROW(fourDofAlignment(vertical, vertical), AlignmentError);
  EXPECT_THROW(fourDofAlignment({Vec3(1, 2, 3)}, {Vec3(0, 0, 0)}), AlignmentError);
  EXPECT_THROW(fourDofAlignment({}, {}), AlignmentError);
  EXPECT_THROW(fourDofAlignment(vertical, {Vec3::Zero()}), AlignmentError);
  // A horizontal line defines the yaw (unlike SE(3), which cannot turn about the line).
  const std::vector<Vec3> line = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)};
  const std::vector<Vec3> turned = {Vec3(5, 5, 1), Vec3(5, 6, 1), Vec3(5, 7, 1)};
  const Similarity3 fit = fourDofAlignment(line, turned);
  EXPECT_NEAR(yawOf(fit.rotation), M_PI / 2, 1e-12);
  EXPECT_LT((fit.apply(line[2]) - turned[2]).norm(), 1e-12);

}
