// The metrics a ground-vehicle claim needs, on planted errors: the 4-DoF (yaw + translation)
// alignment and the ATE after it, the vertical drift, and the roll / pitch / tilt error.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "livo/evaluate/evaluation.hpp"
#include "livo/evaluate/json_report.hpp"
#include "synthetic_trajectory.hpp"

using namespace livo;
using namespace livo::evaluate;

namespace {
constexpr double kRadPerDeg = M_PI / 180.0;

TrajectoryInput timed(const Trajectory& t) {
  TrajectoryInput in;
  in.spec = in.path = "synthetic";
  in.format = "tum";
  in.poses = t;
  return in;
}

Pose3 worldRotation(const Vec3& rotation_vector, const Vec3& translation = Vec3::Zero()) {
  Pose3 T = Pose3::Identity();
  T.linear() = so3::Exp(rotation_vector);
  T.translation() = translation;
  return T;
}

Mat3 zyx(double yaw, double pitch, double roll) {
  return (Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
          Eigen::AngleAxisd(roll, Vec3::UnitX()))
      .toRotationMatrix();
}

/// Every attitude's ZYX pitch and roll moved by the given amounts; yaw and positions unchanged.
Trajectory withAttitudeError(const Trajectory& in, double pitch_error, double roll_error) {
  Trajectory out = in;
  for (auto& s : out) {
    const Mat3 R = s.pose.linear();
    const RollPitch rp = rollPitchOf(R);
    s.pose.linear() = zyx(std::atan2(R(1, 0), R(0, 0)), rp.pitch + pitch_error, rp.roll + roll_error);
  }
  return out;
}

/// Height gained linearly from 0 at the first pose to `total` at the last.
void climb(Trajectory& t, double total) {
  for (size_t i = 0; i < t.size(); ++i)
    t[i].pose.translation().z() += total * static_cast<double>(i) / static_cast<double>(t.size() - 1);
}

/// A straight path along y, 1 m between poses, from the origin.
Trajectory straightAlongY(size_t n) {
  return fixtures::transformed(fixtures::straightTrajectory(n), worldRotation(Vec3(0, 0, M_PI / 2)));
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

TEST(FourDofAlignment, RecoversAPlantedYawAndTranslationExactly) {
  const Trajectory gt = fixtures::wigglyTrajectory(600);
  const double yaw = 0.7;
  const Vec3 shift(3.0, -2.0, 1.5);
  const Trajectory est = fixtures::transformed(gt, worldRotation(Vec3(0, 0, yaw), shift));
  EvaluationOptions options;
  options.alignment = Alignment::kFourDof;
  const Evaluation ev = evaluateTrajectory(timed(est), timed(gt), options);
  EXPECT_NEAR(yawOf(ev.alignment.rotation), -yaw, 1e-12);  // maps the estimate back onto the truth
  EXPECT_LT((ev.alignment.rotation - so3::Exp(Vec3(0, 0, -yaw))).norm(), 1e-12);
  EXPECT_LT((ev.alignment.translation + so3::Exp(Vec3(0, 0, -yaw)) * shift).norm(), 1e-11);
  EXPECT_DOUBLE_EQ(ev.alignment.scale, 1.0);
  EXPECT_LT(ev.ate.max, 1e-10);
  EXPECT_EQ(ev.ate_4dof.count, 600u);
  EXPECT_EQ(ev.ate_4dof.rmse, ev.ate.rmse);  // --align 4dof: the ATE is the 4-DoF ATE
  EXPECT_LT(ev.rpe_rotation_deg.max, 1e-9);

  // Reported beside any other alignment, e.g. SE(3) (the default) and none.
  EXPECT_LT(evaluateTrajectory(timed(est), timed(gt), EvaluationOptions{}).ate_4dof.max, 1e-10);
  options.alignment = Alignment::kNone;
  const Evaluation unaligned = evaluateTrajectory(timed(est), timed(gt), options);
  EXPECT_GT(unaligned.ate.rmse, 1.0);
  EXPECT_LT(unaligned.ate_4dof.max, 1e-10);
}

// A world tilted by 1 deg about x: SE(3) removes it, 4-DoF must not. On a straight path along y
// (y_k = k m, k = 0..N-1) the best yaw is 0 by symmetry and the residual of pose k is
// (cos e - 1, sin e) (y_k - mean y): 2 sin(e / 2) |y_k - mean y|, an RMSE of
// 2 sin(e / 2) sqrt((N^2 - 1) / 12).
TEST(FourDofAlignment, DoesNotRemoveAPlantedRoll) {
  const size_t n = 201;
  const Trajectory gt = straightAlongY(n);
  const double tilt = 1.0 * kRadPerDeg;
  const Trajectory est = fixtures::transformed(gt, worldRotation(Vec3(tilt, 0, 0)));
  EvaluationOptions options;
  options.alignment = Alignment::kFourDof;
  const Evaluation ev = evaluateTrajectory(timed(est), timed(gt), options);
  const double expected = 2.0 * std::sin(tilt / 2.0) * std::sqrt((static_cast<double>(n * n) - 1.0) / 12.0);
  EXPECT_NEAR(yawOf(ev.alignment.rotation), 0.0, 1e-12);
  EXPECT_NEAR(ev.ate.rmse, expected, 1e-9);  // 1.0127 m
  EXPECT_NEAR(ev.ate_4dof.rmse, expected, 1e-9);
  EXPECT_NEAR(ev.ate.max, 2.0 * std::sin(tilt / 2.0) * 100.0, 1e-9);  // the ends, 100 m from the middle

  // On a 3-D path SE(3) takes the tilt out entirely; the 4-DoF ATE keeps it.
  const Trajectory wiggly = fixtures::wigglyTrajectory(600);
  const Evaluation se3 = evaluateTrajectory(timed(fixtures::transformed(wiggly, worldRotation(Vec3(tilt, 0, 0)))),
                                            timed(wiggly), EvaluationOptions{});
  EXPECT_LT(se3.ate.max, 1e-9);
  EXPECT_GT(se3.ate_4dof.rmse, 0.1);
}

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

  // In an evaluation it is then left out (count 0), not an error, unless it was asked for.
  Trajectory standing;
  for (int i = 0; i < 10; ++i) {
    Pose3 T = Pose3::Identity();
    T.translation() = Vec3(1, 2, 0.1 * i);
    standing.push_back({0.1 * i, T});
  }
  EvaluationOptions none;
  none.alignment = Alignment::kNone;
  const Evaluation ev = evaluateTrajectory(timed(standing), timed(standing), none);
  EXPECT_EQ(ev.ate_4dof.count, 0u);
  EXPECT_TRUE(evaluationJson(ev, timed(standing), timed(standing), none)["ate_4dof"].is_null());
  EvaluationOptions four_dof;
  four_dof.alignment = Alignment::kFourDof;
  EXPECT_THROW(evaluateTrajectory(timed(standing), timed(standing), four_dof), EvaluationError);
}

// 0.5 m of height gained linearly over a 200 m straight drive: 0.25 m per 100 m. Heights anchored
// at the first pose, so a yaw and a shift of the estimate's world change nothing.
TEST(VerticalDrift, PlantedDriftPer100Metres) {
  const Trajectory gt = fixtures::straightTrajectory(201);  // 200 m along x
  Trajectory est = gt;
  climb(est, 0.5);
  EvaluationOptions options;
  options.alignment = Alignment::kNone;
  for (const Pose3& world : {Pose3::Identity(), worldRotation(Vec3(0, 0, 2.0), Vec3(12, -7, 3.5))}) {
    const Evaluation ev = evaluateTrajectory(timed(fixtures::transformed(est, world)), timed(gt), options);
    EXPECT_NEAR(ev.vertical.end_m, 0.5, 1e-9);
    EXPECT_NEAR(ev.vertical.path_length_m, 200.0, 1e-9);
    EXPECT_EQ(ev.vertical.path_length_m, ev.end_point.path_length_m);
    EXPECT_NEAR(ev.vertical.per100m(), 0.25, 1e-9);
    EXPECT_NEAR(ev.vertical.max_abs_m, 0.5, 1e-9);
    EXPECT_NEAR(ev.vertical.error_m[100], 0.25, 1e-9);
    EXPECT_NEAR(ev.end_point.translation_m, 0.5, 1e-9);
    EXPECT_LT(ev.attitude.tilt.max, 1e-9);  // positions only
  }
  // Sinking, then back up to 0.1 m below: signed end, largest magnitude over the run.
  Trajectory dip = gt;
  for (size_t i = 0; i < dip.size(); ++i) {
    const double s = static_cast<double>(i);
    dip[i].pose.translation().z() += i <= 100 ? -0.4 * s / 100.0 : -0.4 + 0.3 * (s - 100.0) / 100.0;
  }
  const Evaluation ev = evaluateTrajectory(timed(dip), timed(gt), options);
  EXPECT_NEAR(ev.vertical.end_m, -0.1, 1e-9);
  EXPECT_NEAR(ev.vertical.per100m(), -0.05, 1e-9);
  EXPECT_NEAR(ev.vertical.max_abs_m, 0.4, 1e-9);
}

// What the height-only anchor sees and what it does not: a pitch error of every attitude (positions
// right) is no vertical drift, not even at the first pose; an estimate whose world is tilted by
// 1 deg about y descends 200 sin(1 deg) = 3.49 m too much over the 200 m.
TEST(VerticalDrift, AttitudeErrorsAloneAreNoDriftButATiltedWorldIs) {
  const Trajectory gt = fixtures::straightTrajectory(201);
  EvaluationOptions options;
  options.alignment = Alignment::kNone;
  const Trajectory pitched_est = withAttitudeError(gt, 0.3 * kRadPerDeg, 0.0);
  const Evaluation pitched = evaluateTrajectory(timed(pitched_est), timed(gt), options);
  EXPECT_LT(pitched.vertical.max_abs_m, 1e-12);
  EXPECT_NEAR(pitched.attitude.pitch.rmse, 0.3, 1e-9);
  const Trajectory tilted_est = fixtures::transformed(gt, worldRotation(Vec3(0, kRadPerDeg, 0)));
  const Evaluation tilted = evaluateTrajectory(timed(tilted_est), timed(gt), options);
  EXPECT_NEAR(tilted.vertical.end_m, -200.0 * std::sin(kRadPerDeg), 1e-9);
  EXPECT_NEAR(tilted.vertical.per100m(), -100.0 * std::sin(kRadPerDeg), 1e-9);
  EXPECT_NEAR(tilted.attitude.tilt.max, 1.0, 1e-9);
  EXPECT_LT(tilted.end_point.translation_m, 1e-9);  // the rigid anchor of the end-point drift hides it
}

// A constant 0.3 deg pitch error (ZYX pitch, yaw and roll kept) on a path that turns, rolls and
// pitches: pitch 0.3 deg, roll 0 and tilt 0.3 deg at every pose (the up directions in the body,
// (-sin p, sin r cos p, cos r cos p), differ in p only, by exactly the error), also after a change
// of the estimate's world about z.
TEST(AttitudeError, PlantedPitchAndRollErrors) {
  const Trajectory gt = fixtures::wigglyTrajectory(600);
  const double error = 0.3 * kRadPerDeg;
  const Trajectory pitched = withAttitudeError(gt, error, 0.0);
  EvaluationOptions options;
  for (const Pose3& world : {Pose3(Pose3::Identity()), worldRotation(Vec3(0, 0, 1.3), Vec3(5, -3, 2))}) {
    const Trajectory est = fixtures::transformed(pitched, world);
    const Evaluation ev = evaluateTrajectory(timed(est), timed(gt), options);
    EXPECT_NEAR(ev.attitude.pitch.rmse, 0.3, 1e-9);
    EXPECT_NEAR(ev.attitude.pitch.min, 0.3, 1e-9);
    EXPECT_NEAR(ev.attitude.roll.rmse, 0.0, 1e-9);
    EXPECT_NEAR(ev.attitude.tilt.rmse, 0.3, 1e-9);
    EXPECT_NEAR(ev.attitude.tilt.min, 0.3, 1e-9);
    EXPECT_LT(ev.ate_4dof.max, 1e-9);  // positions untouched
  }
  const Trajectory rolled_est = withAttitudeError(gt, 0.0, -0.2 * kRadPerDeg);
  const Evaluation rolled = evaluateTrajectory(timed(rolled_est), timed(gt), options);
  EXPECT_NEAR(rolled.attitude.roll.rmse, 0.2, 1e-9);
  EXPECT_NEAR(rolled.attitude.roll.max, -0.2, 1e-9);  // signed: estimate minus truth
  EXPECT_NEAR(rolled.attitude.pitch.rmse, 0.0, 1e-9);
}

// An estimate whose world is tilted 1 deg (its gravity is off): the up direction in the body is
// off by exactly 1 deg at every pose, whatever the alignment; the SE(3) alignment that hides the
// tilt from the ATE does not hide it here.
TEST(AttitudeError, TiltedWorldIsSeenWhateverTheAlignment) {
  const Trajectory gt = fixtures::wigglyTrajectory(600);
  const Trajectory est = fixtures::transformed(gt, worldRotation(Vec3(0, 1.0 * kRadPerDeg, 0)));
  for (Alignment mode : {Alignment::kSE3, Alignment::kFourDof, Alignment::kNone}) {
    EvaluationOptions options;
    options.alignment = mode;
    const Evaluation ev = evaluateTrajectory(timed(est), timed(gt), options);
    EXPECT_NEAR(ev.attitude.tilt.min, 1.0, 1e-9) << alignmentName(mode);
    EXPECT_NEAR(ev.attitude.tilt.max, 1.0, 1e-9) << alignmentName(mode);
  }
}

TEST(GroundVehicleMetrics, IdenticalTrajectoriesGiveZeros) {
  const Trajectory gt = fixtures::wigglyTrajectory(600);
  for (Alignment mode : {Alignment::kSE3, Alignment::kFourDof, Alignment::kNone}) {
    EvaluationOptions options;
    options.alignment = mode;
    const Evaluation ev = evaluateTrajectory(timed(gt), timed(gt), options);
    EXPECT_LT(ev.ate_4dof.max, 1e-12) << alignmentName(mode);
    EXPECT_LT(ev.vertical.max_abs_m, 1e-12);
    EXPECT_LT(std::abs(ev.vertical.per100m()), 1e-12);
    EXPECT_GT(ev.vertical.path_length_m, 100.0);
    EXPECT_LT(ev.attitude.roll.rmse, 1e-12);
    EXPECT_LT(ev.attitude.pitch.rmse, 1e-12);
    EXPECT_LT(ev.attitude.tilt.rmse, 1e-12);
  }
}

TEST(GroundVehicleMetrics, JsonCarriesTheNewKeys) {
  const Trajectory gt = fixtures::straightTrajectory(201);
  Trajectory est = withAttitudeError(gt, 0.3 * kRadPerDeg, 0.0);
  climb(est, 0.5);
  EvaluationOptions options;
  options.alignment = Alignment::kFourDof;
  const Evaluation ev = evaluateTrajectory(timed(est), timed(gt), options);
  const nlohmann::json j = evaluationJson(ev, timed(est), timed(gt), options);
  EXPECT_EQ(j["alignment"]["mode"], "4dof");
  EXPECT_DOUBLE_EQ(j["ate_4dof"].get<double>(), ev.ate.rmse);
  // Heights 0.5 i / 200 against 0: after the best z offset, an RMSE of 0.5 sqrt((N^2 - 1) / 12) / 200.
  EXPECT_NEAR(j["ate_4dof"].get<double>(), 0.5 * std::sqrt((201.0 * 201.0 - 1.0) / 12.0) / 200.0, 1e-9);
  EXPECT_NEAR(j["vertical"]["end_m"].get<double>(), 0.5, 1e-9);
  EXPECT_NEAR(j["vertical"]["per_100m"].get<double>(), 0.25, 1e-9);
  EXPECT_NEAR(j["vertical"]["max_abs_m"].get<double>(), 0.5, 1e-9);
  EXPECT_NEAR(j["vertical"]["path_length_m"].get<double>(), 200.0, 1e-9);
  EXPECT_NEAR(j["attitude"]["pitch_rmse_deg"].get<double>(), 0.3, 1e-9);
  EXPECT_NEAR(j["attitude"]["roll_rmse_deg"].get<double>(), 0.0, 1e-9);
  EXPECT_NEAR(j["attitude"]["tilt_rmse_deg"].get<double>(), 0.3, 1e-9);
  EXPECT_NEAR(j["attitude"]["tilt_max_deg"].get<double>(), 0.3, 1e-9);
  // The keys that were there before keep their place.
  for (const char* key :
       {"ate", "rpe", "drift", "end_point", "alignment", "association", "estimate", "ground_truth", "gt_offset"})
    EXPECT_TRUE(j.contains(key)) << key;
}
