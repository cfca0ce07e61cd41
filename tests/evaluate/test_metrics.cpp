// Error statistics, rotation angles, ATE, RPE, KITTI drift, coverage and the body offset on
// trajectories with known transforms and noise.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "livo/evaluate/evaluation.hpp"
#include "synthetic_trajectory.hpp"

using namespace livo;
using namespace livo::evaluate;

namespace {
TrajectoryInput timed(const Trajectory& t, const std::string& name = "synthetic") {
  TrajectoryInput in;
  in.spec = in.path = name;
  in.format = "tum";
  in.poses = t;
  return in;
}

Pose3 rotationZ(double angle) {
  Pose3 T = Pose3::Identity();
  T.linear() = so3::Exp(Vec3(0, 0, angle));
  return T;
}
}  // namespace

TEST(ErrorStatistics, DefinedAsNumpyDefinesThem) {
  const ErrorStatistics s = summarizeErrors({4.0, 1.0, 3.0, 2.0});
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(s.sse, 30.0);
  EXPECT_DOUBLE_EQ(summarizeErrors({5.0, 1.0, 3.0}).median, 3.0);
  EXPECT_EQ(summarizeErrors({}).count, 0u);
}

TEST(RotationAngle, ExactOnRotationsAndAsScipyOffSO3) {
  for (double angle : {0.0, 1e-9, 1e-4, 0.3, 1.7, 3.1, M_PI - 1e-6}) {
    const Vec3 axis = Vec3(0.3, -0.8, 0.5).normalized();
    EXPECT_NEAR(rotationAngle(so3::Exp(angle * axis)), angle, 1e-12) << angle;
  }
  // Slightly non-orthonormal matrices (as KITTI files hold): SciPy 1.10.1's
  // norm(Rotation.from_matrix(M).as_rotvec()), both quaternion branches.
  Mat3 a, b;
  a << 0.9999978750009297, -0.000500699562062615, -0.0019997482501098347, 0.0004989995629376149, 0.9999994750002734,
      -0.00100049912478148, 0.0020000482498910848, 0.0009994991252189798, 0.9999975000010939;
  b << 0.9428322904281532, 0.2853937810927889, -0.1721000177374649, 0.24512627573394719, -0.9437157254427833,
      -0.2220672684955547, -0.22579002488258718, 0.16718558330658195, -0.9597227961229002;
  EXPECT_NEAR(rotationAngle(a), 0.0022911677743079777, 1e-15);
  EXPECT_NEAR(rotationAngle(b), 2.942787661645509, 1e-14);
}

TEST(Evaluate, AlignmentUndoesAKnownTransformAndScale) {
  const Trajectory gt = fixtures::wigglyTrajectory(600);
  EvaluationOptions options;
  // Rigid change of world frame: SE(3) alignment removes it entirely.
  Evaluation ev = evaluateTrajectory(timed(fixtures::transformed(gt, fixtures::somePose())), timed(gt), options);
  EXPECT_EQ(ev.pairs.size(), 600u);
  EXPECT_LT(ev.ate.max, 1e-9);
  EXPECT_LT(ev.rpe_translation_m.max, 1e-9);
  EXPECT_LT(ev.rpe_rotation_deg.max, 1e-9);
  // The alignment maps the estimate back onto the ground truth: the inverse rotation.
  EXPECT_LT((ev.alignment.rotation - fixtures::somePose().linear().transpose()).norm(), 1e-12);

  // Scaled by 0.5 as well: SE(3) leaves an error, Sim(3) recovers the scale 2.
  const Trajectory scaled = fixtures::transformed(gt, fixtures::somePose(), 0.5);
  ev = evaluateTrajectory(timed(scaled), timed(gt), options);
  EXPECT_GT(ev.ate.rmse, 1.0);
  options.alignment = Alignment::kSim3;
  ev = evaluateTrajectory(timed(scaled), timed(gt), options);
  EXPECT_NEAR(ev.alignment.scale, 2.0, 1e-12);
  EXPECT_LT(ev.ate.max, 1e-9);
  EXPECT_LT(ev.rpe_translation_m.max, 1e-9);

  // Without alignment, a pure shift is the error of every pose.
  options.alignment = Alignment::kNone;
  Pose3 shift = Pose3::Identity();
  shift.translation() = Vec3(0.3, -0.4, 0.0);
  ev = evaluateTrajectory(timed(fixtures::transformed(gt, shift)), timed(gt), options);
  EXPECT_NEAR(ev.ate.min, 0.5, 1e-12);
  EXPECT_NEAR(ev.ate.max, 0.5, 1e-12);
  EXPECT_LT(ev.rpe_translation_m.max, 1e-12);  // relative poses do not see it
}

TEST(Evaluate, AteOfIsotropicNoiseIsItsExpectedSize) {
  const Trajectory gt = fixtures::wigglyTrajectory(5000);
  Trajectory est = fixtures::transformed(gt, fixtures::somePose());
  std::mt19937 rng(11);
  const double sigma = 0.02;
  std::normal_distribution<double> noise(0.0, sigma);
  for (auto& s : est) s.pose.translation() += Vec3(noise(rng), noise(rng), noise(rng));
  const Evaluation ev = evaluateTrajectory(timed(est), timed(gt), EvaluationOptions{});
  // |n| for n ~ N(0, sigma^2 I3): rms sqrt(3) sigma, mean 2 sqrt(2/pi) sigma, median 1.5382 sigma.
  // Over 5000 samples their standard errors are below 1 %; the bounds are about four of them.
  EXPECT_NEAR(ev.ate.rmse, std::sqrt(3.0) * sigma, 0.04 * std::sqrt(3.0) * sigma);
  EXPECT_NEAR(ev.ate.mean, 2.0 * std::sqrt(2.0 / M_PI) * sigma, 0.04 * 1.596 * sigma);
  EXPECT_NEAR(ev.ate.median, 1.5382 * sigma, 0.05 * 1.5382 * sigma);
  // Per-step RPE of independent position noise: the difference of two draws, rms sqrt(6) sigma.
  EXPECT_NEAR(ev.rpe_translation_m.rmse, std::sqrt(6.0) * sigma, 0.04 * std::sqrt(6.0) * sigma);
  EXPECT_LT(ev.rpe_rotation_deg.max, 1e-9);  // positions only were disturbed
}

TEST(Evaluate, RpeSeesAConstantPerStepError) {
  const Trajectory gt = fixtures::wigglyTrajectory(400);
  // Each estimated step is the true step followed by a small rotation and translation.
  const double yaw_error = 0.002;  // rad per step
  Pose3 step_error = rotationZ(yaw_error);
  step_error.translation() = Vec3(0.01, -0.02, 0.005);
  Trajectory est = gt;
  for (size_t i = 1; i < est.size(); ++i)
    est[i].pose = est[i - 1].pose * (gt[i - 1].pose.inverse() * gt[i].pose) * step_error;
  EvaluationOptions options;
  options.alignment = Alignment::kNone;
  Evaluation ev = evaluateTrajectory(timed(est), timed(gt), options);
  ASSERT_EQ(ev.rpe_translation_m.count, 399u);
  EXPECT_NEAR(ev.rpe_translation_m.min, step_error.translation().norm(), 1e-9);
  EXPECT_NEAR(ev.rpe_translation_m.max, step_error.translation().norm(), 1e-9);
  EXPECT_NEAR(ev.rpe_rotation_deg.min, yaw_error * 180.0 / M_PI, 1e-8);
  EXPECT_NEAR(ev.rpe_rotation_deg.max, yaw_error * 180.0 / M_PI, 1e-8);

  // Over 4 frames, consecutive (0-4, 4-8, ...) or every pair (0-4, 1-5, ...).
  options.rpe.delta = 4;
  ev = evaluateTrajectory(timed(est), timed(gt), options);
  EXPECT_EQ(ev.rpe.from.size(), 99u);
  EXPECT_EQ(ev.rpe.from[1], 4u);
  options.rpe.all_pairs = true;
  ev = evaluateTrajectory(timed(est), timed(gt), options);
  EXPECT_EQ(ev.rpe.from.size(), 396u);
  EXPECT_EQ(ev.rpe.from[1], 1u);
  EXPECT_EQ(ev.rpe.to[1], 5u);
}

TEST(KittiDrift, ScaleErrorIsThePercentAndYawRateTheDegreesPerMetre) {
  const Trajectory gt = fixtures::straightTrajectory(1001);  // 1000 m, 1 m per pose
  std::vector<Pose3> gt_poses, scaled, turning;
  for (const auto& s : gt) gt_poses.push_back(s.pose);
  // 1 % too long: every relative translation is 1.01 times the true one.
  for (const auto& T : gt_poses) {
    Pose3 S = T;
    S.translation() *= 1.01;
    scaled.push_back(S);
  }
  // A yaw error of 0.001 rad per metre travelled.
  const double yaw_rate = 0.001;
  turning.push_back(gt_poses.front());
  for (size_t i = 1; i < gt_poses.size(); ++i) {
    Pose3 step = Pose3::Identity();
    step.translation() = Vec3(1, 0, 0);
    turning.push_back(turning.back() * step * rotationZ(yaw_rate));
  }

  KittiDriftOptions options;  // 100..800 m every 10 poses
  const KittiDrift d = kittiDrift(gt_poses, scaled, options);
  // A segment of length L from pose i ends at the first pose whose distance exceeds i + L, i + L + 1:
  // its chord is L + 1 m, so the error is 0.01 (L + 1) / L.
  size_t expected_segments = 0;
  double expected_t = 0.0;
  for (size_t l = 0; l < 8; ++l) {
    const double L = 100.0 * static_cast<double>(l + 1);
    size_t n = 0;
    for (size_t i = 0; i < 1001; i += 10)
      if (i + static_cast<size_t>(L) + 1 <= 1000) ++n;
    EXPECT_EQ(d.per_length[l].segments, n) << L;
    EXPECT_NEAR(d.per_length[l].translation_percent, (L + 1.0) / L, 1e-9) << L;
    EXPECT_NEAR(d.per_length[l].rotation_deg_per_m, 0.0, 1e-9);
    expected_segments += n;
    expected_t += static_cast<double>(n) * (L + 1.0) / L;
  }
  EXPECT_EQ(d.segments, expected_segments);
  EXPECT_NEAR(d.translation_percent, expected_t / static_cast<double>(expected_segments), 1e-9);
  EXPECT_NEAR(d.path_length_m, 1000.0, 1e-9);

  const KittiDrift r = kittiDrift(gt_poses, turning, options);
  for (const auto& pl : r.per_length)  // L + 1 steps of yaw_rate over L metres
    EXPECT_NEAR(pl.rotation_deg_per_m, yaw_rate * (pl.length_m + 1.0) / pl.length_m * 180.0 / M_PI, 1e-9);

  // Shorter than every segment: none.
  std::vector<Pose3> short_path(gt_poses.begin(), gt_poses.begin() + 50);
  EXPECT_EQ(kittiDrift(short_path, short_path, options).segments, 0u);
}

TEST(Coverage, GapsLongerThanTheThresholdAreNotCovered) {
  std::vector<double> stamps;
  for (int i = 0; i <= 300; ++i) stamps.push_back(0.1 * i);     // 0 .. 30 s
  for (int i = 600; i <= 1000; ++i) stamps.push_back(0.1 * i);  // 60 .. 100 s
  const Coverage c = groundTruthCoverage(stamps, 0.0, 100.0, 0.0);
  EXPECT_NEAR(c.gap, 0.3, 1e-12);
  EXPECT_NEAR(c.covered, 70.0, 1e-9);
  EXPECT_NEAR(c.fraction, 0.7, 1e-11);
  // A gap threshold above 30 s counts the hole as covered.
  EXPECT_NEAR(groundTruthCoverage(stamps, 0.0, 100.0, 31.0).fraction, 1.0, 1e-11);
  // Starting late costs the missed part of the span.
  EXPECT_NEAR(groundTruthCoverage(stamps, -25.0, 100.0, 0.0).fraction, 70.0 / 125.0, 1e-11);
  EXPECT_DOUBLE_EQ(groundTruthCoverage({}, 0.0, 10.0, 0.0).fraction, 0.0);
  EXPECT_DOUBLE_EQ(groundTruthCoverage({5.0}, 5.0, 5.0, 0.0).fraction, 1.0);
}

TEST(Evaluate, CoverageOfAnEstimateThatLosesTrack) {
  const Trajectory gt = fixtures::wigglyTrajectory(1000, 20.0);  // 50 s at 20 Hz
  Trajectory est;
  for (size_t i = 0; i < gt.size(); i += 2)  // 10 Hz, lost between 20 s and 30 s
    if (gt[i].stamp - gt.front().stamp < 20.0 || gt[i].stamp - gt.front().stamp >= 30.0) est.push_back(gt[i]);
  const Evaluation ev = evaluateTrajectory(timed(est), timed(gt), EvaluationOptions{});
  EXPECT_NEAR(ev.coverage.gap, 0.3, 1e-9);
  // Covered: 0 .. 19.9 and 30 .. 49.9 of a 49.95 s span.
  EXPECT_NEAR(ev.coverage.fraction, (19.9 + 19.9) / 49.95, 1e-9);
}

TEST(Evaluate, GtOffsetMovesTheEstimateToThePrism) {
  const Trajectory body = fixtures::wigglyTrajectory(300);
  const Vec3 prism(-0.29, 0.05, 0.33);  // in the body frame
  Trajectory prism_track = body;
  applyBodyOffset(prism_track, prism);
  EXPECT_NEAR((prism_track[10].pose.translation() - body[10].pose.translation()).norm(), prism.norm(), 1e-12);
  EvaluationOptions options;
  options.alignment = Alignment::kNone;
  EXPECT_NEAR(evaluateTrajectory(timed(body), timed(prism_track), options).ate.max, prism.norm(), 1e-12);
  options.gt_offset = prism;
  EXPECT_LT(evaluateTrajectory(timed(body), timed(prism_track), options).ate.max, 1e-12);
}

TEST(Evaluate, ClearErrorsWhenNothingPairsOrAlignmentIsImpossible) {
  const Trajectory gt = fixtures::wigglyTrajectory(100, 10.0, 1000.0);
  const Trajectory est = fixtures::wigglyTrajectory(100, 10.0, 0.0);
  try {
    evaluateTrajectory(timed(est, "est.tum"), timed(gt, "gt.tum"), EvaluationOptions{});
    FAIL() << "nothing associates";
  } catch (const EvaluationError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("no estimated pose lies within 0.01 s"), std::string::npos) << m;
    EXPECT_NE(m.find("est.tum"), std::string::npos) << m;
    EXPECT_NE(m.find("gt.tum"), std::string::npos) << m;
  }
  // Two pairs cannot be aligned; without alignment they can be evaluated.
  const Trajectory two(gt.begin(), gt.begin() + 2);
  EXPECT_THROW(evaluateTrajectory(timed(two), timed(gt), EvaluationOptions{}), EvaluationError);
  EvaluationOptions none;
  none.alignment = Alignment::kNone;
  EXPECT_EQ(evaluateTrajectory(timed(two), timed(gt), none).ate.count, 2u);

  EvaluationOptions bad;
  bad.rpe.delta = 0;
  EXPECT_THROW(evaluateTrajectory(timed(gt), timed(gt), bad), std::invalid_argument);
  EXPECT_THROW(parseAlignment("affine"), std::invalid_argument);
}

// End-point drift: anchored at the first pose, so a change of world frame costs nothing, while a
// heading error at the start grows into a known end error; the path length is the truth's.
TEST(Evaluate, EndPointDriftAnchorsAtTheFirstPose) {
  const Trajectory gt = fixtures::wigglyTrajectory(600);
  EvaluationOptions options;
  Evaluation ev = evaluateTrajectory(timed(fixtures::transformed(gt, fixtures::somePose())), timed(gt), options);
  EXPECT_LT(ev.end_point.translation_m, 1e-9);
  EXPECT_LT(ev.end_point.rotation_deg, 1e-9);
  double length = 0.0;
  for (size_t i = 1; i < gt.size(); ++i) length += (gt[i].pose.translation() - gt[i - 1].pose.translation()).norm();
  EXPECT_NEAR(ev.end_point.path_length_m, length, 1e-9);

  // every estimated pose after the first rotated by 1 degree of yaw about the first position
  Trajectory est = gt;
  const Vec3 p0 = gt.front().pose.translation();
  Pose3 yaw = Pose3::Identity();
  yaw.linear() = Eigen::AngleAxisd(M_PI / 180.0, Vec3::UnitZ()).toRotationMatrix();
  yaw.translation() = p0 - yaw.linear() * p0;
  for (size_t i = 1; i < est.size(); ++i) est[i].pose = yaw * est[i].pose;
  ev = evaluateTrajectory(timed(est), timed(gt), options);
  const Vec3 pn = gt.back().pose.translation();
  const Vec3 d = pn - p0;
  const double expected = 2.0 * std::sin(M_PI / 360.0) * std::hypot(d.x(), d.y());
  EXPECT_NEAR(ev.end_point.translation_m, expected, 1e-9);
  EXPECT_NEAR(ev.end_point.rotation_deg, 1.0, 1e-9);
  EXPECT_NEAR(ev.end_point.percent(), 100.0 * expected / length, 1e-9);
}
