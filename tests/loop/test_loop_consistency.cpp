// The consistency check before a loop enters the graph: false loops planted into a drifting run
// (registration results between places 7-13 m apart claimed as the same place, or off by 1.5 m
// and 5 deg; near candidates off by 0.5 m and 1 deg) are refused, the true loops still enter, and the trajectory is
// what it is without the planted loops; with the check off the same plants enter and bend the trajectory.
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <set>

#include <gtest/gtest.h>

#include "livo/loop/loop_closer.hpp"
#include "livo/loop/loop_consistency.hpp"
#include "livo/loop/voxel_grid.hpp"
#include "synthetic_scenes.hpp"

namespace livo::loop {
namespace {
using namespace livo::loop::testing;

// Two laps and a bit of a 14 m circle, a keyframe every 10 deg (2.4 m), with odometry drifting
// as the default drift model allows: 3e-4 rad of yaw and 0.3 % of scale per step.
struct DriftingLaps {
  static constexpr int kPerLap = 36;
  std::vector<Pose3> truth, odometry;
  explicit DriftingLaps(int total) {
    for (int i = 0; i < total; ++i) {
      const double a = 2 * M_PI * i / kPerLap;
      truth.push_back(yawPose(a + M_PI / 2, Vec3(14 * std::cos(a), 14 * std::sin(a), 1.8)));
    }
    odometry.push_back(truth[0]);
    for (int i = 1; i < total; ++i) {
      Pose3 rel = truth[i - 1].inverse() * truth[i];
      rel.linear() = Eigen::AngleAxisd(3e-4, Vec3::UnitZ()).toRotationMatrix() * rel.linear();
      rel.translation() *= 1.003;
      odometry.push_back(odometry.back() * rel);
    }
  }
};

// Keyframe i of a run: the odometry's pose, a keyframe every 2 s, the scene seen from the truth.
KeyframeInput lapKeyframe(const std::vector<Pose3>& truth, const std::vector<Pose3>& odometry, const Points& scene,
                          size_t i) {
  KeyframeInput in;
  in.id = static_cast<int64_t>(i);
  in.utime = 1000000 + in.id * 2000000;
  in.pose = odometry[i];
  const Pose3& T = truth[i];
  in.cloud = viewFrom(scene, T.translation(), std::atan2(T.linear()(1, 0), T.linear()(0, 0)), 20.0, 0.02, 100 + i);
  return in;
}

struct LapRun {
  std::unique_ptr<LoopCloser> closer;
  std::shared_ptr<std::set<std::pair<int64_t, int64_t>>> planted =
      std::make_shared<std::set<std::pair<int64_t, int64_t>>>();  // (from, to), filled by the hook
  double worst = 0.0;                                             // m, final keyframe poses against the truth
};

// What the registration says of the candidates 7-13 m away (which it registers correctly here)
// and of the near candidates of every third keyframe of the second lap: as it is, nothing
// (refused: the runs without false loops), or false loops.
enum class Far { kAsIs, kNothing, kFalseLoop };
LapRun runLaps(const DriftingLaps& laps, const Points& scene, bool check, Far far, const GicpResult& realistic) {
  LapRun run;
  LoopCloserOptions o;
  o.merge_distance = 0.0;  // every keyframe a node: every pass is a loop candidate
  o.consistency_check = check;
  if (far != Far::kAsIs)
    o.registration_hook = [&laps, &realistic, far, planted = run.planted, plants = 0](
                              int64_t from, int64_t to, LoopRegistrationResult& r) mutable {
      const Pose3 T = laps.truth[to].inverse() * laps.truth[from];  // G = I: no roll or pitch
      const double d = T.translation().norm();
      const bool far_pair = d >= 7.0 && d <= 13.0;
      const bool near_pair = from >= 40 && from % 3 == 0 && d < 4.0;
      if (!far_pair && !near_pair) return;
      if (far == Far::kNothing) {
        r.accepted = false;
        r.reason = "withheld by the test";
        return;
      }
      // a registration that "succeeded" between places that look alike: as confident as a real one
      r.accepted = true;
      r.reason.clear();
      r.fine = realistic;
      r.T_target_source = T;
      if (near_pair) {  // a near miss the odometry alone would allow: 0.5 m and 1 deg
        r.T_target_source.translation() += Vec3(0.0, 0.5, 0.0);
        r.T_target_source.linear() =
            r.T_target_source.linear() * Eigen::AngleAxisd(0.0175, Vec3::UnitZ()).toRotationMatrix();
      } else if (plants++ % 2 == 0) {
        r.T_target_source.translation().setZero();  // "the same place": off by d
      } else {
        r.T_target_source.translation() += Vec3(0.0, 1.5, 0.0);  // a subtler one: 1.5 m and 5 deg
        r.T_target_source.linear() =
            r.T_target_source.linear() * Eigen::AngleAxisd(0.087, Vec3::UnitZ()).toRotationMatrix();
      }
      planted->insert({from, to});
    };
  run.closer = std::make_unique<LoopCloser>(o);
  for (size_t i = 0; i < laps.truth.size(); ++i) {
    const KeyframeInput in = lapKeyframe(laps.truth, laps.odometry, scene, i);
    run.closer->addKeyframe(in);
  }
  run.closer->forEachPose(
      [&](int64_t id, const Pose3& pose) { run.worst = std::max(run.worst, translationError(pose, laps.truth[id])); });
  return run;
}

std::set<std::pair<int64_t, int64_t>> pairs(const LoopCloser& c) {
  std::set<std::pair<int64_t, int64_t>> out;
  for (const AcceptedLoop& l : c.loops()) out.insert({l.from_id, l.to_id});
  return out;
}

TEST(LoopConsistency, PlantedFalseLoopsAreRefusedAndTrueOnesStillEnter) {
  const Points scene = makeScene(41, 0.15);
  const DriftingLaps laps(2 * DriftingLaps::kPerLap + 6);
  // the information a real registration of two keyframes 2.4 m apart claims
  const GicpCloud a =
      GicpCloud::build(centroidPerVoxel(viewFrom(scene, laps.truth[0].translation(), M_PI / 2, 20.0, 0.02, 1), 0.4));
  const GicpCloud b = GicpCloud::build(
      centroidPerVoxel(viewFrom(scene, laps.truth[1].translation(), M_PI / 2 + M_PI / 18, 20.0, 0.02, 2), 0.4));
  const GicpResult realistic = gicpRegister(b, a, laps.truth[0].inverse() * laps.truth[1], {});
  ASSERT_TRUE(realistic.converged);

  const LapRun as_is = runLaps(laps, scene, true, Far::kAsIs, {});
  const LapRun as_is_unchecked = runLaps(laps, scene, false, Far::kAsIs, {});
  const LapRun clean = runLaps(laps, scene, true, Far::kNothing, {});
  const LapRun planted = runLaps(laps, scene, true, Far::kFalseLoop, realistic);
  const LapRun planted_unchecked = runLaps(laps, scene, false, Far::kFalseLoop, realistic);
  const double drift = translationError(laps.odometry.back(), laps.truth.back());
  std::printf("[loop-consistency] all candidates as registered: %zu loops, none refused, worst %.3f m\n",
              as_is.closer->loops().size(), as_is.worst);
  std::printf(
      "[loop-consistency] odometry drift %.2f m; without the far candidates: %zu loops, worst %.3f m; %zu planted: %zu "
      "refused, "
      "%zu loops, worst %.3f m; unchecked with the plants: %zu loops, worst %.3f m\n",
      drift, clean.closer->loops().size(), clean.worst, planted.planted->size(), planted.closer->refusedLoops().size(),
      planted.closer->loops().size(), planted.worst, planted_unchecked.closer->loops().size(), planted_unchecked.worst);
  for (const RefusedLoop& f : planted.closer->refusedLoops())
    std::printf("[loop-consistency]   refused %ld -> %ld: %s\n", long(f.from_id), long(f.to_id), f.reason.c_str());

  // the true loops pass the check: it refuses none and keeps the loops of an unchecked run
  ASSERT_GE(as_is.closer->loops().size(), 8u);
  EXPECT_TRUE(as_is.closer->refusedLoops().empty());
  EXPECT_EQ(pairs(*as_is.closer), pairs(*as_is_unchecked.closer));
  ASSERT_GE(clean.closer->loops().size(), 4u);
  EXPECT_TRUE(clean.closer->refusedLoops().empty());
  EXPECT_GT(drift, 0.3);                // there was something to correct ...
  EXPECT_LT(clean.worst, 0.5 * drift);  // ... and the loops did

  // every planted loop is refused, nothing else is, and the true loops enter as without plants
  ASSERT_GE(planted.planted->size(), 4u);
  EXPECT_EQ(planted.closer->refusedLoops().size(), planted.planted->size());
  size_t against_loop = 0;
  for (const RefusedLoop& f : planted.closer->refusedLoops()) {
    EXPECT_EQ(planted.planted->count({f.from_id, f.to_id}), 1u) << f.from_id << " -> " << f.to_id;
    EXPECT_GT(f.chi2, LoopCloserOptions{}.consistency_chi2);
    against_loop += f.against == "loop";
  }
  EXPECT_GE(against_loop, 1u);  // some only the cycle through an earlier loop caught
  EXPECT_EQ(pairs(*planted.closer), pairs(*clean.closer));
  for (const auto& [id, pose] : clean.closer->graph().poses())
    EXPECT_LT(translationError(planted.closer->graph().pose(id), pose), 1e-9) << id;
  EXPECT_NEAR(planted.worst, clean.worst, 1e-9);

  // without the check the same plants enter and bend the trajectory
  EXPECT_GT(planted_unchecked.closer->loops().size(), clean.closer->loops().size());
  EXPECT_GT(planted_unchecked.worst, 3 * clean.worst);
}

// The odometry's own covariance (keyframe_t.relative_covariance) in the graph and in the correction
// gate: a loop the odometry satisfies within its covariance changes nothing; one that it does not
// corrects; an increment without a covariance (or not from the previous keyframe) gets the drift
// model, as before.
constexpr double kChi2SixP99 = 16.812;  // 6 degrees of freedom, p = 0.99

struct GivenCovariance {
  double rotation_sigma = 0.0;     // rad per increment (0: none given)
  double translation_sigma = 0.0;  // m per increment
  bool from_previous = true;       // relative_to_id is the previous keyframe's id
};

std::unique_ptr<LoopCloser> runWithGivenCovariance(const std::vector<Pose3>& truth, const std::vector<Pose3>& odometry,
                                                   const Points& scene, const GivenCovariance& given,
                                                   bool from_filter = true,
                                                   const std::function<void(LoopCloserOptions&)>& adjust = {}) {
  LoopCloserOptions o;
  o.merge_distance = 0.0;
  o.odometry_covariance_from_filter = from_filter;
  o.correction_chi2 = kChi2SixP99;
  if (adjust) adjust(o);
  auto closer = std::make_unique<LoopCloser>(o);
  for (size_t i = 0; i < truth.size(); ++i) {
    KeyframeInput in = lapKeyframe(truth, odometry, scene, i);
    if (given.rotation_sigma > 0.0) {
      in.relative_to_id = given.from_previous ? in.id - 1 : in.id - 2;
      in.relative_covariance.setZero();
      in.relative_covariance.diagonal() << Vec3::Constant(given.rotation_sigma * given.rotation_sigma),
          Vec3::Constant(given.translation_sigma * given.translation_sigma);
    }
    closer->addKeyframe(in);
  }
  return closer;
}

double worstAgainst(const LoopCloser& closer, const std::vector<Pose3>& reference) {
  double worst = 0.0;
  closer.forEachPose(
      [&](int64_t id, const Pose3& pose) { worst = std::max(worst, translationError(pose, reference[id])); });
  return worst;
}

size_t corrections(const LoopCloser& closer) {
  size_t n = 0;
  for (const AcceptedLoop& l : closer.loops()) n += l.corrected;
  return n;
}

TEST(LoopConsistency, TheOdometrysCovarianceDecidesWhetherALoopCorrects) {
  const Points scene = makeScene(41, 0.15);
  const DriftingLaps laps(2 * DriftingLaps::kPerLap + 6);
  // an exact odometry that says so (0.01 deg, 2 mm per 2.4 m increment): the loops it satisfies
  // within that and the registrations' own uncertainty change nothing
  const auto exact = runWithGivenCovariance(laps.truth, laps.truth, scene, {1.75e-4, 2e-3});
  ASSERT_GE(exact->loops().size(), 8u);
  EXPECT_EQ(corrections(*exact), 0u);
  EXPECT_LT(worstAgainst(*exact, laps.truth), 1e-9);
  for (const AcceptedLoop& l : exact->loops()) {
    EXPECT_LE(l.correction_chi2, kChi2SixP99) << l.from_id << " -> " << l.to_id;
    EXPECT_GT(l.odometry_covariance(5, 5), 0.0);
  }
  // the drift model alone would have corrected it with these loops (their residuals pass 2 cm / 0.1 deg)
  const auto drift_model = runWithGivenCovariance(laps.truth, laps.truth, scene, {}, false);
  std::printf(
      "[loop-covariance] exact odometry: %zu loops, %zu corrections with its covariance, %zu with the drift model\n",
      exact->loops().size(), corrections(*exact), corrections(*drift_model));

  // the drifting odometry (0.34 m; 3e-4 rad and 7 mm off per increment) saying so: the loops
  // disagree with it beyond what that adds up to (a random walk: 2.5e-3 rad over a lap against the
  // 0.011 rad it drifts), correct it, and the graph bends it back
  const auto drifting = runWithGivenCovariance(laps.truth, laps.odometry, scene, {3e-4, 7e-3});
  const double drift = translationError(laps.odometry.back(), laps.truth.back());
  std::printf("[loop-covariance] drifting odometry %.2f m: %zu loops, %zu corrections, worst %.3f m\n", drift,
              drifting->loops().size(), corrections(*drifting), worstAgainst(*drifting, laps.truth));
  EXPECT_GT(drift, 0.3);
  EXPECT_GE(corrections(*drifting), 1u);
  EXPECT_LT(worstAgainst(*drifting, laps.truth), 0.5 * drift);

  // a covariance not from the previous keyframe is not used: the run is the drift model's
  const auto skipped = runWithGivenCovariance(laps.truth, laps.odometry, scene, {3e-4, 7e-3, false});
  const auto model = runWithGivenCovariance(laps.truth, laps.odometry, scene, {}, false);
  EXPECT_EQ(pairs(*skipped), pairs(*model));
  for (const auto& [id, pose] : model->graph().poses())
    EXPECT_LT(translationError(skipped->graph().pose(id), pose), 1e-12) << id;
}

// The optimum decides (correction_from_optimum), not the loop's residual alone: an exact odometry
// that says how sure it is (0.01 deg, 2 mm per increment) and loops 4 cm off that say they are
// good to 10 cm. Every loop's residual passes 2 cm and the chi-square gate is off, so without the
// optimum each loop corrected and pulled the exact trajectory towards the loops; with it the graph
// weighs them against the odometry, the keyframe hardly moves, and nothing is published. A drifting
// odometry that says so is still corrected.
TEST(LoopConsistency, ACorrectionIsPublishedOnlyWhereTheOptimumMovesTheKeyframe) {
  const Points scene = makeScene(41, 0.15);
  const DriftingLaps laps(2 * DriftingLaps::kPerLap + 6);
  const auto unsure_offset_loops = [](bool from_optimum) {
    return [from_optimum](LoopCloserOptions& o) {
      o.correction_chi2 = 0.0;
      o.correction_from_optimum = from_optimum;
      o.registration_information = false;
      o.loop_translation_sigma = 0.1;
      o.registration_hook = [](int64_t, int64_t, LoopRegistrationResult& r) {
        if (r.accepted) r.T_target_source.translation() += Vec3(0.04, 0.0, 0.0);
      };
    };
  };
  const GivenCovariance sure{1.75e-4, 2e-3};
  const auto with_optimum =
      runWithGivenCovariance(laps.truth, laps.truth, scene, sure, true, unsure_offset_loops(true));
  const auto residual_only =
      runWithGivenCovariance(laps.truth, laps.truth, scene, sure, true, unsure_offset_loops(false));
  ASSERT_GE(with_optimum->loops().size(), 8u);
  double largest_shift = 0.0, smallest_residual = 1.0;
  for (const AcceptedLoop& l : with_optimum->loops()) {
    largest_shift = std::max(largest_shift, l.optimum_shift_translation);
    smallest_residual = std::min(smallest_residual, l.residual_translation);
  }
  std::printf(
      "[loop-optimum] exact odometry, loops 4 cm off: %zu loops (residuals from %.3f m), %zu corrections and "
      "worst %.4f m with the optimum deciding (largest shift %.4f m); %zu corrections and worst %.4f m on the "
      "residual alone\n",
      with_optimum->loops().size(), smallest_residual, corrections(*with_optimum),
      worstAgainst(*with_optimum, laps.truth), largest_shift, corrections(*residual_only),
      worstAgainst(*residual_only, laps.truth));
  EXPECT_GE(smallest_residual, 0.02);          // every loop passes the residual gate
  EXPECT_GE(corrections(*residual_only), 3u);  // the control: on the residual alone they correct
  EXPECT_EQ(corrections(*with_optimum), 0u);
  EXPECT_LT(largest_shift, 0.02);

  const auto drifting = runWithGivenCovariance(laps.truth, laps.odometry, scene, {3e-4, 7e-3}, true,
                                               [](LoopCloserOptions& o) { o.correction_chi2 = 0.0; });
  const double drift = translationError(laps.odometry.back(), laps.truth.back());
  std::printf("[loop-optimum] drifting odometry %.2f m: %zu corrections, worst %.3f m\n", drift, corrections(*drifting),
              worstAgainst(*drifting, laps.truth));
  EXPECT_GE(corrections(*drifting), 1u);
  EXPECT_LT(worstAgainst(*drifting, laps.truth), 0.5 * drift);
}

// The held calibration's part of the increments (keyframe_t.relative_covariance_held_calibration) is
// one error for the whole run, not noise per increment: the LiDAR mount's telescopes over a chain and
// is in the loops' registrations alike. Composed increment by increment it made the odometry look
// metres unsure between the two ends of parking_hard's loops (README, Limits), and every loop pulled
// the graph all the way. Here an exact odometry whose filter is sure (0.01 deg, 2 mm an increment)
// adds a held part of 0.04 deg and 6 mm an increment (parking_hard's), and loops 4 cm off say they
// are good to 10 cm: composed, the held part lets them correct it; left out (compose_held_calibration
// false) the odometry over the lap is the filter's and nothing is published. The loops' odometry
// covariance is then exactly the filter part's, and an odometry that drifts and says so in its
// filter's part is still corrected.
TEST(LoopConsistency, TheHeldCalibrationIsNotComposedAsNoisePerIncrement) {
  const Points scene = makeScene(41, 0.15);
  const DriftingLaps laps(2 * DriftingLaps::kPerLap + 6);
  // the filter's part and the held part of every increment (standard deviations per axis: rad, m)
  // (corrupt_held: the held part as sent is not finite, the whole as above)
  const auto run = [&](const std::vector<Pose3>& odometry, Vec2 filter, Vec2 held, bool compose, double offset,
                       bool corrupt_held = false) {
    LoopCloserOptions o;
    o.merge_distance = 0.0;
    o.compose_held_calibration = compose;
    if (offset != 0.0) {  // loops `offset` off that say they are good to 10 cm; else as registered
      o.registration_information = false;
      o.loop_translation_sigma = 0.1;
      o.registration_hook = [offset](int64_t, int64_t, LoopRegistrationResult& r) {
        if (r.accepted) r.T_target_source.translation() += Vec3(offset, 0.0, 0.0);
      };
    }
    auto closer = std::make_unique<LoopCloser>(o);
    for (size_t i = 0; i < laps.truth.size(); ++i) {
      KeyframeInput in = lapKeyframe(laps.truth, odometry, scene, i);
      in.relative_to_id = in.id - 1;
      in.relative_covariance_held_calibration.setZero();
      in.relative_covariance_held_calibration.diagonal() << Vec3::Constant(held(0) * held(0)),
          Vec3::Constant(held(1) * held(1));
      in.relative_covariance = in.relative_covariance_held_calibration;
      in.relative_covariance.diagonal() +=
          (Vec6() << Vec3::Constant(filter(0) * filter(0)), Vec3::Constant(filter(1) * filter(1))).finished();
      if (corrupt_held) in.relative_covariance_held_calibration(0, 0) = std::nan("");
      closer->addKeyframe(in);
    }
    return closer;
  };
  const Vec2 sure(1.75e-4, 2e-3), held(7e-4, 6e-3);
  const auto composed = run(laps.truth, sure, held, true, 0.04);
  const auto filter_part = run(laps.truth, sure, held, false, 0.04);
  const auto nothing_held = run(laps.truth, sure, Vec2::Zero(), true, 0.04);
  ASSERT_GE(filter_part->loops().size(), 8u);
  ASSERT_EQ(pairs(*filter_part), pairs(*nothing_held));
  for (size_t k = 0; k < filter_part->loops().size(); ++k)
    EXPECT_LT((filter_part->loops()[k].odometry_covariance - nothing_held->loops()[k].odometry_covariance).norm(),
              1e-12 * nothing_held->loops()[k].odometry_covariance.norm());
  const double composed_sigma = std::sqrt(composed->loops().front().odometry_covariance(3, 3));
  const double filter_sigma = std::sqrt(filter_part->loops().front().odometry_covariance(3, 3));
  std::printf(
      "[loop-held] exact odometry, loops 4 cm off (10 cm stated): held part composed: odometry sigma %.3f m over "
      "the first loop, %zu corrections, worst %.4f m; the filter's part: %.3f m, %zu corrections, worst %.4f m\n",
      composed_sigma, corrections(*composed), worstAgainst(*composed, laps.truth), filter_sigma,
      corrections(*filter_part), worstAgainst(*filter_part, laps.truth));
  EXPECT_GT(composed_sigma, 3 * filter_sigma);
  EXPECT_GE(corrections(*composed), 1u);  // the control: composed, the held part lets the loops pull
  EXPECT_EQ(corrections(*filter_part), 0u);
  EXPECT_LT(worstAgainst(*filter_part, laps.truth), 0.02);
  EXPECT_EQ(filter_part->unusableHeldParts(), 0);

  // a held part that is not finite: the whole covariance is composed (as if compose_held_calibration),
  // not the drift model, and the closer counts the increments
  const auto corrupt = run(laps.truth, sure, held, false, 0.04, true);
  EXPECT_EQ(corrupt->unusableHeldParts(), static_cast<int64_t>(laps.truth.size()) - 1);
  ASSERT_EQ(pairs(*corrupt), pairs(*composed));
  EXPECT_EQ(corrections(*corrupt), corrections(*composed));
  for (size_t k = 0; k < corrupt->loops().size(); ++k)
    EXPECT_EQ(corrupt->loops()[k].odometry_covariance, composed->loops()[k].odometry_covariance);
  composed->forEachPose([&](int64_t id, const Pose3& T) { EXPECT_EQ(corrupt->pose(id).matrix(), T.matrix()); });

  // the drifting odometry (3e-4 rad and 7 mm off per increment) saying so in its filter's part,
  // with the loops as registered
  const auto drifting = run(laps.odometry, Vec2(3e-4, 7e-3), held, false, 0.0);
  const double drift = translationError(laps.odometry.back(), laps.truth.back());
  std::printf("[loop-held] drifting odometry %.2f m, the filter's part: %zu corrections, worst %.3f m\n", drift,
              corrections(*drifting), worstAgainst(*drifting, laps.truth));
  EXPECT_GE(corrections(*drifting), 1u);
  EXPECT_LT(worstAgainst(*drifting, laps.truth), 0.5 * drift);
}

// Every registration tilted 0.3 deg in roll (what a 16-beam LiDAR's loops are off by, README):
// the corrected poses and the corrections keep the odometry's roll and pitch, which it measures
// against gravity, and the loops still take out the heading drift. Keyframes that join an older
// node hang from it through the loop's measurement; without the levelling (gravity priors off,
// the control) that measurement's tilt reaches the corrections: a LIO adopting them tilted its
// state and its map by it on every correction, and diverged within 60 of them.
struct TiltedRun {
  std::unique_ptr<LoopCloser> closer;
  std::vector<Correction> corrections;
  double worst_tilt_deg = 0.0;             // keyframe poses: their up axis against the odometry's
  double worst_correction_tilt_deg = 0.0;  // T_Ck_O's rotation of the world's up axis
};

TiltedRun runWithTiltedLoops(const DriftingLaps& laps, const Points& scene, double gravity_prior_sigma) {
  TiltedRun run;
  LoopCloserOptions o;
  o.gravity_prior_sigma = gravity_prior_sigma;
  o.registration_hook = [](int64_t, int64_t, LoopRegistrationResult& r) {
    if (r.accepted) r.T_target_source.linear() = r.T_target_source.linear() * so3::Exp(Vec3(0.3 * M_PI / 180, 0, 0));
  };
  run.closer = std::make_unique<LoopCloser>(o);
  for (size_t i = 0; i < laps.truth.size(); ++i) {
    const KeyframeInput in = lapKeyframe(laps.truth, laps.odometry, scene, i);
    const AddResult r = run.closer->addKeyframe(in);
    if (!r.correction) continue;
    run.corrections.push_back(*r.correction);
    run.worst_correction_tilt_deg = std::max(
        run.worst_correction_tilt_deg, angleBetweenDeg(r.correction->T_Ck_O.linear() * Vec3::UnitZ(), Vec3::UnitZ()));
  }
  run.closer->forEachPose([&](int64_t id, const Pose3& pose) {
    const Vec3 up = laps.odometry[static_cast<size_t>(id)].linear().transpose() * Vec3::UnitZ();
    run.worst_tilt_deg = std::max(run.worst_tilt_deg, angleBetweenDeg(pose.linear().transpose() * Vec3::UnitZ(), up));
  });
  return run;
}

TEST(LoopConsistency, CorrectionsKeepTheOdometrysRollAndPitch) {
  const Points scene = makeScene(41, 0.15);
  const DriftingLaps laps(2 * DriftingLaps::kPerLap + 6);
  const TiltedRun levelled = runWithTiltedLoops(laps, scene, LoopCloserOptions{}.gravity_prior_sigma);
  const TiltedRun control = runWithTiltedLoops(laps, scene, 0.0);
  const double drift = translationError(laps.odometry.back(), laps.truth.back());
  std::printf(
      "[loop-tilt] loops tilted 0.3 deg: %zu loops, %zu corrections; worst tilt of a corrected pose %.2g deg, "
      "of a correction %.2g deg; worst error %.3f m against the odometry's %.3f m. Without the levelling: "
      "%zu corrections, worst tilt %.3f deg (pose) and %.3f deg (correction)\n",
      levelled.closer->loops().size(), levelled.corrections.size(), levelled.worst_tilt_deg,
      levelled.worst_correction_tilt_deg, worstAgainst(*levelled.closer, laps.truth), drift, control.corrections.size(),
      control.worst_tilt_deg, control.worst_correction_tilt_deg);
  // the scene shows the failure: without the levelling the loops' tilt reaches the corrections
  ASSERT_GE(control.corrections.size(), 3u);
  EXPECT_GT(control.worst_correction_tilt_deg, 0.1);
  // with it, nothing tilts, and the heading drift is still taken out
  ASSERT_GE(levelled.corrections.size(), 3u);
  EXPECT_LT(levelled.worst_tilt_deg, 1e-6);
  EXPECT_LT(levelled.worst_correction_tilt_deg, 1e-6);
  EXPECT_LT(worstAgainst(*levelled.closer, laps.truth), 0.5 * drift);
}

// The drift model: a heading drift's lever arm dominates the translation over long paths.
TEST(LoopConsistency, DriftCovarianceGrowsWithThePath) {
  const DriftModel m;
  const Mat6 short_path = driftCovariance(0.0, m), long_path = driftCovariance(100.0, m);
  EXPECT_NEAR(std::sqrt(short_path(0, 0)), m.rotation_floor, 1e-12);
  EXPECT_NEAR(std::sqrt(short_path(3, 3)), m.translation_floor, 1e-12);
  EXPECT_NEAR(std::sqrt(long_path(0, 0)), std::hypot(m.rotation_floor, 100 * m.rotation_per_m), 1e-12);
  // 0.5 m of scale-like drift and 1 m of lever arm (2e-4 rad/m over 100 m, half of it on average)
  EXPECT_NEAR(std::sqrt(long_path(3, 3)), std::sqrt(2e-3 * 2e-3 + 0.5 * 0.5 + 1.0), 1e-9);
  // a pose 1 m off along x against the long path's prediction: chi2 = 1 / var
  const Pose3 off = yawPose(0.0, Vec3(1, 0, 0));
  EXPECT_NEAR(poseChi2(Pose3::Identity(), long_path, off, Mat6::Zero()), 1.0 / long_path(3, 3), 1e-9);
}

}  // namespace
}  // namespace livo::loop
