// "Where the estimate was weak": stretches of flagged sweeps, the weak direction in words, the
// section's text on synthetic outputs (busy and quiet), weak_spots.json back and forth, and the
// same read from a recorded outputs log.
#include <gtest/gtest.h>

#include <lcm/lcm-cpp.hpp>

#include "evaluate/lcm_log_writer.hpp"
#include "livo/filter_state_t.hpp"
#include "livo/keyframe_t.hpp"
#include "livo/messages.hpp"
#include "livo/odometry_t.hpp"
#include "livo/reason_counts.hpp"
#include "livo/report/weak_spots.hpp"
#include "temp_path.hpp"

using namespace livo;
using namespace livo::report;

namespace {

constexpr double kStart = 100.0;  // stamp of the first sweep, s
constexpr double kPeriod = 0.1;   // s between sweeps

double sweepStamp(size_t i) { return kStart + kPeriod * static_cast<double>(i); }

/// 100 sweeps along x at 1 m/s, body x forward. Degenerate: 20-49 (position uncertain along x)
/// and 60-61 and 90; no LiDAR residual: 0 (seeds the map) and 70-72.
PipelineOutputs corridorOutputs() {
  PipelineOutputs o;
  for (size_t i = 0; i < 100; ++i) {
    Pose3 T = Pose3::Identity();
    T.translation() = Vec3(0.1 * static_cast<double>(i), 0.0, 0.0);
    o.odometry.push_back({sweepStamp(i), T});
    o.odometry_frames.push_back({});
    OdometryQuality q;
    q.degenerate = (i >= 20 && i < 50) || i == 60 || i == 61 || i == 90;
    q.num_residuals = i == 0 || (i >= 70 && i < 73) ? 0 : 500;
    q.velocity = Vec3(1.0, 0.0, 0.0);
    q.position_covariance = q.degenerate ? Vec3(0.04, 1e-4, 2e-4).asDiagonal() : Vec3(1e-4, 1e-4, 1e-4).asDiagonal();
    o.odometry_quality.push_back(q);
  }
  return o;
}

void addVisual(PipelineOutputs* o) {
  o->state_priors = 40;
  for (size_t i = 0; i < 40; ++i) {
    const bool kept = i == 5 || i == 6 || i == 7 || i == 30;
    o->visual_answers.push_back({kStart + 0.25 * static_cast<double>(i), "vio", !kept});
  }
  ReasonCounts kept;
  kept.add("no image at the prior's time (a newer image came)");
  kept.add("no image at the prior's time (a newer prior came)");
  kept.add("too few patches (3)");
  kept.add("too few patches (5)");
  health_t h{};
  h.node = "vio";
  h.message = kept.summary("priors kept");
  o->final_health["vio"] = h;
}

void addLoop(PipelineOutputs* o) {
  o->keyframes.push_back({3, sweepStamp(10), Pose3::Identity(), {}});
  o->keyframes.push_back({17, sweepStamp(95), Pose3::Identity(), {}});
  LoopEvent e;
  e.correction_id = 1;
  e.stamp = sweepStamp(95);
  e.from_id = 17;
  e.to_id = 3;
  e.shift_m = 0.42;
  e.turn_deg = 1.25;
  o->loops.push_back(e);
}

bool contains(const std::string& text, const std::string& what) { return text.find(what) != std::string::npos; }

}  // namespace

TEST(WeakSpots, MergesConsecutiveFlaggedSamplesIntoSpans) {
  const std::vector<double> t = {0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7};
  const std::vector<TimeSpan> s = mergeFlaggedRuns(t, {true, true, false, false, true, false, true, true});
  ASSERT_EQ(s.size(), 3u);
  EXPECT_DOUBLE_EQ(s[0].from, 0.0);
  EXPECT_DOUBLE_EQ(s[0].to, 0.1);
  EXPECT_EQ(s[0].count, 2);
  EXPECT_DOUBLE_EQ(s[1].from, 0.4);  // one sample: from = to
  EXPECT_DOUBLE_EQ(s[1].to, 0.4);
  EXPECT_EQ(s[1].count, 1);
  EXPECT_DOUBLE_EQ(s[2].from, 0.6);  // a run to the end is closed
  EXPECT_DOUBLE_EQ(s[2].to, 0.7);
  EXPECT_TRUE(mergeFlaggedRuns(t, std::vector<bool>(t.size(), false)).empty());
  EXPECT_EQ(mergeFlaggedRuns(t, std::vector<bool>(t.size(), true)).size(), 1u);
  EXPECT_TRUE(mergeFlaggedRuns({}, {}).empty());
  EXPECT_THROW(mergeFlaggedRuns(t, {true}), std::invalid_argument);
}

TEST(WeakSpots, LongestFirstByDurationThenSamplesThenTime) {
  const std::vector<TimeSpan> s =
      longestFirst({{0.0, 0.2, 3}, {1.0, 1.5, 6}, {2.0, 2.0, 1}, {3.0, 3.2, 3}, {4.0, 4.2, 4}});
  ASSERT_EQ(s.size(), 5u);
  EXPECT_DOUBLE_EQ(s[0].from, 1.0);
  EXPECT_DOUBLE_EQ(s[1].from, 4.0);  // 0.2 s and 4 samples
  EXPECT_DOUBLE_EQ(s[2].from, 0.0);  // 0.2 s, 3 samples: the earlier first
  EXPECT_DOUBLE_EQ(s[3].from, 3.0);
  EXPECT_DOUBLE_EQ(s[4].from, 2.0);
}

TEST(WeakSpots, NamesTheWeakDirectionAgainstTheMotionAndTheBody) {
  const Mat3 along_x = Vec3(1.0, 0.01, 0.01).asDiagonal();
  const Mat3 I = Mat3::Identity();
  EXPECT_EQ(describe(weakAxis(along_x, Vec3(1.0, 0.0, 0.0), I)), "along the direction of travel (body x)");
  EXPECT_EQ(describe(weakAxis(along_x, Vec3(-0.8, 0.1, 0.0), I)), "along the direction of travel (body x)");
  EXPECT_EQ(describe(weakAxis(along_x, Vec3(0.0, 1.0, 0.0), I)), "across the direction of travel (body x)");
  EXPECT_EQ(describe(weakAxis(along_x, Vec3(1.0, 1.0, 0.0), I)), "oblique to the direction of travel (body x)");
  EXPECT_EQ(describe(weakAxis(along_x, Vec3::Zero(), I)), "horizontally, at rest (body x)");
  EXPECT_EQ(describe(weakAxis(Vec3(0.01, 0.01, 1.0).asDiagonal(), Vec3(1.0, 0.0, 0.0), I)), "vertically (body z)");
  // the body turned 90 deg about z: world x is its y axis
  EXPECT_EQ(describe(weakAxis(along_x, Vec3(1.0, 0.0, 0.0), so3::Exp(Vec3(0.0, 0.0, M_PI / 2)))),
            "along the direction of travel (body y)");
  // between two body axes: no axis named
  EXPECT_EQ(describe(weakAxis(along_x, Vec3(1.0, 0.0, 0.0), so3::Exp(Vec3(0.0, 0.0, M_PI / 4)))),
            "along the direction of travel");
  // two directions about as uncertain: none singled out
  EXPECT_EQ(weakAxis(Vec3(1.0, 0.8, 0.01).asDiagonal(), Vec3(1.0, 0.0, 0.0), I).direction, WeakDirection::kNoSingle);
  EXPECT_EQ(weakAxis(Mat3::Zero(), Vec3(1.0, 0.0, 0.0), I).direction, WeakDirection::kNoSingle);
}

TEST(WeakSpots, SectionOnACorridorWithAVioAndALoop) {
  PipelineOutputs o = corridorOutputs();
  addVisual(&o);
  addLoop(&o);
  const WeakSpots w = findWeakSpots(o);
  EXPECT_DOUBLE_EQ(w.start, kStart);
  EXPECT_EQ(w.sweeps, 100);
  EXPECT_EQ(w.degenerate, 33);
  ASSERT_EQ(w.degenerate_stretches.size(), 3u);
  EXPECT_EQ(w.degenerate_stretches[0].span.count, 30);
  EXPECT_EQ(w.direction, "along the direction of travel (body x)");
  EXPECT_DOUBLE_EQ(w.direction_share, 1.0);
  EXPECT_EQ(w.predicted, 3);  // 70-72; sweep 0 seeds the map
  ASSERT_EQ(w.predicted_spans.size(), 1u);
  ASSERT_EQ(w.visual.size(), 1u);
  EXPECT_EQ(w.visual[0].refused, 4);
  EXPECT_EQ(w.visual[0].of, 40);
  EXPECT_EQ(w.visual[0].reasons.at("no image at the prior's time"), 2);
  EXPECT_EQ(w.visual[0].spans.size(), 2u);
  ASSERT_EQ(w.loops.size(), 1u);
  EXPECT_DOUBLE_EQ(w.loops[0].from_stamp, sweepStamp(95));

  const std::string md = weakSpotsMarkdown(w);
  EXPECT_TRUE(contains(md, "## Where the estimate was weak")) << md;
  EXPECT_TRUE(contains(md, "33 of 100 (33.0 %) in 3 stretches")) << md;
  EXPECT_TRUE(contains(md, "along the direction of travel (body x) on 100 % of them")) << md;
  // longest first, in seconds since the first sweep
  EXPECT_TRUE(contains(md,
                       "| 2.0 | 4.9 | 30 | along the direction of travel (body x) |\n"
                       "| 6.0 | 6.1 | 2 | along the direction of travel (body x) |\n"
                       "| 9.0 | 9.0 | 1 |"))
      << md;
  EXPECT_TRUE(contains(md, "3 of 100 sweeps (3.0 %): 7.0–7.2 s (3).")) << md;
  EXPECT_TRUE(contains(md,
                       "- vio: 4 of 40 images (10.0 %; priors kept): 2 × no image at the prior's time, "
                       "2 × too few patches; when: 1.2–1.8 s (3), 7.5 s (1)."))
      << md;
  EXPECT_TRUE(contains(md, "**Loop closures**: 1, at 9.5 s.")) << md;
  EXPECT_TRUE(contains(md, "| 9.5 | 17 (9.5 s) and 3 (1.0 s) | 0.420 m, 1.25 deg |")) << md;

  // weak_spots.json carries it all: the section from the file is the same
  EXPECT_EQ(weakSpotsMarkdown(weakSpotsFromJson(nlohmann::json::parse(weakSpotsJson(w).dump()))), md);
}

TEST(WeakSpots, QuietRunIsShort) {
  PipelineOutputs o = corridorOutputs();
  for (OdometryQuality& q : o.odometry_quality) {
    q.degenerate = false;
    q.num_residuals = 500;
  }
  const std::string md = weakSpotsMarkdown(findWeakSpots(o));
  EXPECT_TRUE(contains(md,
                       "**Degenerate sweeps** (`ODOMETRY.degenerate`: the LiDAR left some direction to the "
                       "prediction): none of 100.\n"))
      << md;
  EXPECT_TRUE(contains(md, "update** (`ODOMETRY.num_residuals` 0 after an epoch's first sweep): none.\n")) << md;
  EXPECT_TRUE(contains(md, "**Images the VIO did not use**: no VIO ran.\n")) << md;
  EXPECT_TRUE(contains(md, "**Loop closures**: none.\n")) << md;
  EXPECT_FALSE(contains(md, "|")) << md;  // no table
  EXPECT_LT(std::count(md.begin(), md.end(), '\n'), 14) << md;
}

TEST(WeakSpots, ListsTheTenLongestStretchesAndCountsTheRest) {
  PipelineOutputs o = corridorOutputs();
  for (size_t i = 0; i < o.odometry_quality.size(); ++i)
    o.odometry_quality[i].degenerate = i % 3 == 0 || (i >= 30 && i < 35);  // 1-sweep stretches and one of 6
  const WeakSpots w = findWeakSpots(o);
  const std::string md = weakSpotsMarkdown(w);
  EXPECT_TRUE(contains(md, "| 3.0 | 3.4 | 5 |")) << md;  // 30-34, the longest, first
  const size_t rows = static_cast<size_t>(std::count(md.begin(), md.end(), '\n'));
  EXPECT_GT(rows, 10u);
  const std::string rest =
      "and " + std::to_string(w.degenerate_stretches.size() - kListedStretches) + " shorter stretches (";
  EXPECT_TRUE(contains(md, rest)) << md;
  EXPECT_TRUE(contains(md, "at most 1 each).")) << md;
}

TEST(WeakSpots, ListsTheTenLargestLoopCorrections) {
  PipelineOutputs o = corridorOutputs();
  for (int k = 0; k < 12; ++k) {
    LoopEvent e;
    e.correction_id = k + 1;
    e.stamp = sweepStamp(static_cast<size_t>(50 + 4 * k));
    e.from_id = 20 + k;
    e.to_id = k;
    e.shift_m = 0.01 * (k + 1);  // the last is the largest
    e.turn_deg = 0.1;
    o.loops.push_back(e);
  }
  const std::string md = weakSpotsMarkdown(findWeakSpots(o));
  EXPECT_TRUE(contains(md,
                       "**Loop closures**: 12, from 5.0 to 9.4 s; each moved the newest keyframe by 0.070 m "
                       "(median), at most 0.120 m and 0.10 deg; the largest:"))
      << md;
  EXPECT_TRUE(contains(md, "| 9.4 | 31 and 11 | 0.120 m, 0.10 deg |\n| 9.0 | 30 and 10 | 0.110 m")) << md;
  EXPECT_TRUE(contains(md, "| 5.8 | 22 and 2 | 0.030 m, 0.10 deg |\n\nand 2 smaller ones.")) << md;
}

TEST(WeakSpots, AVioThatNeverAnswered) {
  PipelineOutputs o = corridorOutputs();
  o.state_priors = 12;
  EXPECT_TRUE(contains(weakSpotsMarkdown(findWeakSpots(o)),
                       "no VIO answered the 12 images lio handed over (it went on LiDAR-only)."));
}

TEST(WeakSpots, AFeatureVioCountsItsImagesFromHealth) {
  PipelineOutputs o = corridorOutputs();
  ReasonCounts refused;
  refused.add("before the visual state was initialised (waiting for the IMU at rest)", 7);
  refused.add("image not later than the previous one");
  health_t h{};
  h.node = "vio_feature";
  h.message = refused.summary("images refused");
  channel_stats_t camera{};
  camera.channel = "CAMERA";
  camera.messages = 200;
  h.channels = {camera};
  h.num_channels = 1;
  o.final_health["vio_feature"] = h;
  const WeakSpots w = findWeakSpots(o);
  ASSERT_EQ(w.visual.size(), 1u);
  EXPECT_EQ(w.visual[0].refused, 8);
  EXPECT_EQ(w.visual[0].of, 200);
  EXPECT_TRUE(contains(weakSpotsMarkdown(w),
                       "- vio_feature: 8 of 200 images (4.0 %; images refused): 7 × before the "
                       "visual state was initialised, 1 × image not later than the previous one."));
}

TEST(WeakSpots, ReadFromARecordedOutputsLog) {
  const std::string path = livo_test::tempPath("weak_outputs.lcmlog");
  {
    lcm::LogFile log(path, "w");
    for (int i = 0; i < 30; ++i) {
      const int64_t t = 5000000 + i * 100000;
      odometry_t o{};
      o.utime = t;
      poseTo(Pose3::Identity(), o.position, o.orientation);
      o.velocity[1] = 1.2;  // travelling along y
      o.degenerate = i >= 10 && i < 20;
      o.num_residuals = i == 25 ? 0 : 300;
      matrixTo<6>(Mat6(Vec6(1e-4, 1e-4, 1e-4, 1e-4, o.degenerate ? 0.09 : 1e-4, 1e-4).asDiagonal()), o.pose_covariance);
      fixtures::writeMessage(log, "ODOMETRY", t, o);
      if (i % 5 == 0) {
        filter_state_t s{};
        s.utime = t;
        s.source = "vio";
        s.valid = i != 15;
        fixtures::writeMessage(log, "STATE_PRIOR", t, s);
        fixtures::writeMessage(log, "STATE_POSTERIOR", t, s);
      }
    }
    for (int id : {0, 1}) {
      keyframe_t k{};
      k.id = id;
      k.utime = id == 0 ? 5000000 : 7900000;
      poseTo(Pose3::Identity(), k.position, k.orientation);
      k.cloud.frame = "I";
      fixtures::writeMessage(log, "KEYFRAME", k.utime, k);
    }
    loop_correction_t lc{};
    lc.utime = 7900000;
    lc.correction_id = 1;
    lc.loop_from_id = 1;
    lc.loop_to_id = 0;
    Pose3 step = Pose3::Identity();
    step.translation() = Vec3(0.3, 0.0, 0.0);
    poseTo(step, lc.correction_position, lc.correction_orientation);
    poseTo(step, lc.odometry_to_corrected_position, lc.odometry_to_corrected_orientation);
    lc.num_keyframes = 2;
    lc.keyframe_id = {0, 1};
    lc.position = {{0.0, 0.0, 0.0}, {0.3, 0.0, 0.0}};
    lc.orientation = {{1.0, 0.0, 0.0, 0.0}, {1.0, 0.0, 0.0, 0.0}};
    fixtures::writeMessage(log, "LOOP_CORRECTION", 7900000, lc);
  }
  const PipelineOutputs out = readPipelineOutputs(path);
  ASSERT_EQ(out.odometry_quality.size(), 30u);
  EXPECT_EQ(out.state_priors, 6);
  ASSERT_EQ(out.visual_answers.size(), 6u);
  ASSERT_EQ(out.loops.size(), 1u);
  EXPECT_NEAR(out.loops[0].shift_m, 0.3, 1e-12);
  const WeakSpots w = findWeakSpots(out);
  EXPECT_EQ(w.degenerate, 10);
  ASSERT_EQ(w.degenerate_stretches.size(), 1u);
  EXPECT_NEAR(w.degenerate_stretches[0].span.from, 6.0, 1e-9);
  EXPECT_NEAR(w.degenerate_stretches[0].span.to, 6.9, 1e-9);
  EXPECT_EQ(w.degenerate_stretches[0].direction, "along the direction of travel (body y)");
  EXPECT_EQ(w.predicted, 1);
  ASSERT_EQ(w.visual.size(), 1u);
  EXPECT_EQ(w.visual[0].refused, 1);
  EXPECT_TRUE(w.visual[0].reasons.empty());  // no HEALTH said why
  EXPECT_TRUE(contains(weakSpotsMarkdown(w), "the reasons are not in its HEALTH (see logs/vio.log)"));
  EXPECT_NEAR(w.loops[0].to_stamp, 5.0, 1e-9);
}
