// livo-loop's node on memq://: synthetic keyframes around a loop with injected drift; the
// published correction brings the keyframes back to the truth. Bad input is refused, not fatal.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "livo/loop/loop_node.hpp"
#include "livo/loop/pose_graph.hpp"
#include "livo/loop_correction_t.hpp"
#include "livo/messages.hpp"
#include "synthetic_scenes.hpp"
#include "temp_path.hpp"

namespace livo::loop {
namespace {
using namespace livo::loop::testing;

void drain(lcm::LCM& lcm) {
  while (lcm.handleTimeout(0) > 0) {
  }
}

keyframe_t makeKeyframe(int64_t id, const Pose3& pose, const Points& cloud) {
  keyframe_t k{};
  k.id = id;
  k.utime = 1000000 + id * 2000000;  // one keyframe every 2 s
  poseTo(pose, k.position, k.orientation);
  for (int i = 0; i < 36; ++i) k.pose_covariance[i] = 0.0;
  k.cloud.frame = "I";
  k.cloud.utime = k.utime;
  for (const Vec3& p : cloud) {
    k.cloud.x.push_back(static_cast<float>(p.x()));
    k.cloud.y.push_back(static_cast<float>(p.y()));
    k.cloud.z.push_back(static_cast<float>(p.z()));
  }
  k.cloud.num_points = static_cast<int32_t>(cloud.size());
  k.cloud.intensity.assign(cloud.size(), 0.0f);
  k.cloud.time_offset.assign(cloud.size(), 0.0f);
  k.cloud.ring.assign(cloud.size(), -1);
  return k;
}

// How the simulated odometry takes the corrections it hears.
enum class Adoption {
  kIgnores,             // never: every keyframe has correction_id 0
  kBeforeNextKeyframe,  // before its next keyframe (livo-lio under lockstep replay)
  kTwoKeyframesLate,    // two keyframes later (real time: keyframes published before adoption
                        // arrive after the correction, still in the previous frame)
};

// The node as the tests run it: quiet, no health messages.
NodeOptions quietNode(const std::string& name) {
  NodeOptions no;
  no.name = name;
  no.quiet = true;
  no.health_period_s = 0;
  return no;
}

// A loop of 36 keyframes with a yaw bias and a scale error in the odometry, run once more past
// the start.
struct DriftedLoop {
  static constexpr int kPerLap = 36, kTotal = kPerLap + 6;
  std::vector<Pose3> truth, odo;
};

DriftedLoop driftedLoop() {
  DriftedLoop d;
  for (int i = 0; i < DriftedLoop::kTotal; ++i) {
    const double a = 2 * M_PI * i / DriftedLoop::kPerLap;
    d.truth.push_back(yawPose(a + M_PI / 2, Vec3(14 * std::cos(a), 14 * std::sin(a), 1.8)));
  }
  d.odo.push_back(d.truth[0]);
  for (int i = 1; i < DriftedLoop::kTotal; ++i) {  // yaw bias and 2 % scale error per step
    Pose3 rel = d.truth[i - 1].inverse() * d.truth[i];
    rel.linear() = Eigen::AngleAxisd(0.006, Vec3::UnitZ()).toRotationMatrix() * rel.linear();
    rel.translation() *= 1.02;
    d.odo.push_back(d.odo.back() * rel);
  }
  return d;
}

// What the simulated odometry heard: the corrections, each with the keyframe index it arrived after.
struct Heard {
  std::optional<loop_correction_t> last;
  int corrections = 0;
  int64_t adopted_id = 0;  // the newest correction the odometry adopted
  std::vector<std::pair<int, loop_correction_t>> arrivals;
};

// Publishes the drifted loop's keyframes as the odometry would (adopting the corrections it hears
// as `adoption` says), with bad input on the way, and listens to the corrections.
Heard publishDriftedLoop(lcm::LCM& lcm, const DriftedLoop& loop, Adoption adoption) {
  const Points scene = makeScene(41, 0.15);
  Heard heard;
  Pose3 adopted = Pose3::Identity();  // the odometry's frame <- its raw frame
  int index = 0;
  NodeOptions listener_options = quietNode("listener");
  listener_options.publish_progress = false;
  Node listener(lcm, listener_options);
  listener.subscribe<loop_correction_t>("LOOP_CORRECTION", [&](const loop_correction_t& m) {
    heard.last = m;
    ++heard.corrections;
    heard.arrivals.push_back({index, m});
  });
  const int delay = adoption == Adoption::kTwoKeyframesLate ? 2 : 0;
  std::vector<Pose3> published;
  for (int i = 0; i < DriftedLoop::kTotal; ++i) {
    index = i;
    for (const auto& [after, m] : heard.arrivals)
      if (adoption != Adoption::kIgnores && m.correction_id > heard.adopted_id && i - 1 - after >= delay) {
        adopted = poseFrom(m.odometry_to_corrected_position, m.odometry_to_corrected_orientation);
        heard.adopted_id = m.correction_id;
      }
    const Pose3& T = loop.truth[i];
    const Points cloud =
        viewFrom(scene, T.translation(), std::atan2(T.linear()(1, 0), T.linear()(0, 0)), 20.0, 0.02, 100 + i);
    published.push_back(adopted * loop.odo[i]);
    keyframe_t k = makeKeyframe(i, published.back(), cloud);
    k.correction_id = heard.adopted_id;
    lcm.publish("KEYFRAME", &k);
    drain(lcm);
    if (i == 10) {  // bad input on the way: a NaN pose and a repeated id are refused
      keyframe_t bad = makeKeyframe(11, loop.odo[i], {});
      bad.position[0] = std::numeric_limits<double>::quiet_NaN();
      lcm.publish("KEYFRAME", &bad);
      keyframe_t repeated = makeKeyframe(5, loop.odo[i], cloud);
      lcm.publish("KEYFRAME", &repeated);
      drain(lcm);
    }
  }
  return heard;
}

// The last correction brings the keyframes back near the truth, and the closer's final poses too;
// its odometry edges are the raw odometry increments whatever frame the poses came in.
void expectCorrectedToTruth(const LoopCloser& closer, const DriftedLoop& loop, const Heard& heard) {
  const std::vector<Pose3>& truth = loop.truth;
  const std::vector<Pose3>& odo = loop.odo;
  const int total = DriftedLoop::kTotal;
  const loop_correction_t& last = *heard.last;
  const double drift = translationError(odo[total - 1], truth[total - 1]);
  // The graph's odometry edges are the raw odometry increments whatever frame the poses came in.
  for (const PoseEdge& e : closer.graph().edges())
    if (!e.is_loop) {
      EXPECT_LT(translationError(e.T_from_to, odo[e.from].inverse() * odo[e.to]), 1e-9) << e.from;
      EXPECT_LT(rotationErrorDeg(e.T_from_to, odo[e.from].inverse() * odo[e.to]), 1e-9) << e.from;
    }
  double worst = 0.0;
  for (int i = 0; i < last.num_keyframes; ++i) {
    const Pose3 corrected = poseFrom(last.position[i].data(), last.orientation[i].data());
    worst = std::max(worst, translationError(corrected, truth[last.keyframe_id[i]]));
  }
  // One loop cannot undo a 2 % scale error exactly: the graph spreads it around the loop.
  EXPECT_LT(worst, 0.2 * drift) << "drift " << drift;
  const int n = last.num_keyframes;
  const Pose3 newest = poseFrom(last.position[n - 1].data(), last.orientation[n - 1].data());
  const double rotation_drift = rotationErrorDeg(odo[total - 1], truth[total - 1]);
  EXPECT_LT(translationError(newest, truth[last.keyframe_id[n - 1]]), 0.1 * drift);
  EXPECT_LT(rotationErrorDeg(newest, truth[last.keyframe_id[n - 1]]), 0.1 * rotation_drift);
  // The final keyframe trajectory: every keyframe, also those after the last correction.
  double worst_final = 0.0;
  closer.forEachPose(
      [&](int64_t id, const Pose3& pose) { worst_final = std::max(worst_final, translationError(pose, truth[id])); });
  EXPECT_LT(worst_final, 0.2 * drift);
  // odometry_to_corrected maps the raw pose of the keyframe that closed the loop onto its optimised one
  const Pose3 T_Ck_O = poseFrom(last.odometry_to_corrected_position, last.odometry_to_corrected_orientation);
  EXPECT_LT(translationError(T_Ck_O * odo[last.loop_from_id], closer.pose(last.loop_from_id)), 1e-9);
  std::printf(
      "[loop-node] drift %.2f m, worst corrected keyframe %.3f m (final graph %.3f m), newest %.3f m / %.3f deg, "
      "%d corrections\n",
      drift, worst, worst_final, translationError(newest, truth[last.keyframe_id[n - 1]]),
      rotationErrorDeg(newest, truth[last.keyframe_id[n - 1]]), heard.corrections);
}

// An adopting odometry publishes its keyframe poses in the corrected frame and says which
// correction they include (keyframe_t.correction_id).
void runDriftedLoop(Adoption adoption) {
  SCOPED_TRACE(adoption == Adoption::kIgnores              ? "odometry ignores corrections"
               : adoption == Adoption::kBeforeNextKeyframe ? "odometry adopts corrections at once"
                                                           : "odometry adopts corrections two keyframes late");
  const DriftedLoop loop = driftedLoop();
  const int total = DriftedLoop::kTotal;
  lcm::LCM lcm("memq://");
  LoopNodeOptions lo;
  lo.output_dir = livo_test::tempPath("loop-out");
  // The graph's odometry noise model says how bad this odometry is (2 % of the distance, 0.006 rad
  // per 2.4 m step), else the graph would trust it over the loop.
  lo.core.odometry_translation_per_m = 0.02;
  lo.core.odometry_rotation_per_m = 2.5e-3;
  LoopNode node(lcm, quietNode("loop"), lo);
  const Heard heard = publishDriftedLoop(lcm, loop, adoption);
  EXPECT_EQ(node.closer().size(), static_cast<size_t>(total));
  for (const AcceptedLoop& l : node.closer().loops())
    std::printf("[loop-node] loop %ld -> %ld: error vs truth %.3f m %.3f deg\n", long(l.from_id), long(l.to_id),
                translationError(l.T_to_from, loop.truth[l.to_id].inverse() * loop.truth[l.from_id]),
                rotationErrorDeg(l.T_to_from, loop.truth[l.to_id].inverse() * loop.truth[l.from_id]));
  ASSERT_GE(heard.corrections, 1);
  ASSERT_TRUE(heard.last.has_value());
  ASSERT_GT(heard.last->num_keyframes, DriftedLoop::kPerLap);  // the loop closes on the way past the start
  EXPECT_GT(translationError(loop.odo[total - 1], loop.truth[total - 1]), 3.0);
  if (adoption != Adoption::kIgnores) {
    ASSERT_GT(heard.adopted_id, 0);
    EXPECT_EQ(heard.last->correction_id, heard.corrections);  // 1, 2, ...
  }
  if (adoption == Adoption::kTwoKeyframesLate) {  // keyframes in the previous frame came after a correction
    bool stale_after_correction = false;
    for (const auto& [after, m] : heard.arrivals) stale_after_correction |= after + 1 < total;
    EXPECT_TRUE(stale_after_correction);
  }
  expectCorrectedToTruth(node.closer(), loop, heard);

  node.writeOutputs();
  EXPECT_TRUE(std::filesystem::exists(lo.output_dir + "/loops.json"));
  EXPECT_TRUE(std::filesystem::exists(lo.output_dir + "/global_map.ply"));
  std::ifstream tum(lo.output_dir + "/keyframes.tum");
  int lines = 0;
  for (std::string line; std::getline(tum, line);)
    if (!line.empty() && line[0] != '#') ++lines;
  EXPECT_EQ(lines, total);
}

TEST(LoopNode, CorrectionBringsDriftedLoopBackToTruth) { runDriftedLoop(Adoption::kIgnores); }

TEST(LoopNode, OdometryThatAdoptsCorrectionsGetsTheSameCorrection) { runDriftedLoop(Adoption::kBeforeNextKeyframe); }

// Real time: keyframes published before the odometry adopted a correction arrive after it.
TEST(LoopNode, KeyframesPublishedBeforeAdoptionKeepRawOdometryEdges) { runDriftedLoop(Adoption::kTwoKeyframesLate); }

// An odometry reset (epoch 1) at keyframe 20: the odometry restarts at the origin. No odometry
// edge across it, a segment of its own held in its raw poses, and the edges inside each epoch are
// the true raw increments.
TEST(LoopNode, OdometryResetStartsANewGraphSegment) {
  const Points scene = makeScene(41, 0.15);
  lcm::LCM lcm("memq://");
  LoopNodeOptions lo;
  lo.output_dir = livo_test::tempPath("loop-epochs");
  LoopNode node(lcm, quietNode("loop"), lo);
  const int total = 30, reset_at = 20;
  std::vector<Pose3> raw;            // as published: each epoch in its own raw frame
  Pose3 origin = Pose3::Identity();  // of the current epoch
  for (int i = 0; i < total; ++i) {
    const double a = 2 * M_PI * i / 36;
    const Pose3 truth = yawPose(a + M_PI / 2, Vec3(14 * std::cos(a), 14 * std::sin(a), 1.8));
    if (i == reset_at) origin = truth;
    raw.push_back(origin.inverse() * truth);
    keyframe_t k = makeKeyframe(i, raw.back(), viewFrom(scene, truth.translation(), a + M_PI / 2, 20.0, 0.02, 100 + i));
    k.epoch = i >= reset_at ? 1 : 0;
    lcm.publish("KEYFRAME", &k);
    drain(lcm);
  }
  // a keyframe of the old epoch after the reset, and one in a correction loop never published
  keyframe_t late = makeKeyframe(total, raw.back(), {});
  lcm.publish("KEYFRAME", &late);
  keyframe_t unknown = makeKeyframe(total + 1, raw.back(), {});
  unknown.epoch = 1;
  unknown.correction_id = 7;
  lcm.publish("KEYFRAME", &unknown);
  drain(lcm);
  ASSERT_EQ(node.closer().size(), static_cast<size_t>(total));
  EXPECT_EQ(node.closer().odometryEdgesAcrossEpochs(), 0u);
  int odometry_edges = 0;
  for (const PoseEdge& e : node.closer().graph().edges()) {
    if (e.is_loop) continue;
    ++odometry_edges;
    EXPECT_NE(e.to, reset_at) << "an odometry edge into the first keyframe of epoch 1";
    EXPECT_LT(translationError(e.T_from_to, raw[e.from].inverse() * raw[e.to]), 1e-9) << e.from;
    EXPECT_LT(rotationErrorDeg(e.T_from_to, raw[e.from].inverse() * raw[e.to]), 1e-9) << e.from;
  }
  EXPECT_EQ(odometry_edges, total - 2);
  EXPECT_EQ(node.closer().graph().pose(reset_at).translation().norm(), 0.0);  // its own origin
  int64_t rejected = -1;
  for (const channel_stats_t& c : node.node().healthMessage().channels)
    if (c.channel == "KEYFRAME") rejected = c.rejected;
  EXPECT_EQ(rejected, 2);
  node.writeOutputs();
  std::ifstream json(lo.output_dir + "/loops.json");
  const std::string text((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"odometry_edges_across_epochs\": 0"), std::string::npos) << text;
  EXPECT_NE(text.find("\"first_id\": 20"), std::string::npos) << text;
}

// The keyframe features are derived from the clouds on disk on demand, with an LRU cache: the
// loops, the graph and the map do not depend on the cache size (1: every candidate derived from
// the stored cloud; 1000: all kept, as before the store).
TEST(LoopCloser, ResultsDoNotDependOnTheFeatureCacheSize) {
  const Points scene = makeScene(41, 0.15);
  const int per_lap = 36, total = per_lap + 6;
  auto run = [&](int cache) {
    LoopCloserOptions o;
    o.feature_cache_keyframes = cache;
    o.odometry_translation_per_m = 0.02;
    o.odometry_rotation_per_m = 2.5e-3;
    auto closer = std::make_unique<LoopCloser>(o);
    Pose3 odo = Pose3::Identity();
    Pose3 previous_truth = Pose3::Identity();
    for (int i = 0; i < total; ++i) {
      const double a = 2 * M_PI * i / per_lap;
      const Pose3 truth = yawPose(a + M_PI / 2, Vec3(14 * std::cos(a), 14 * std::sin(a), 1.8));
      if (i == 0) {
        odo = truth;
      } else {
        Pose3 rel = previous_truth.inverse() * truth;
        rel.linear() = Eigen::AngleAxisd(0.006, Vec3::UnitZ()).toRotationMatrix() * rel.linear();
        rel.translation() *= 1.02;
        odo = odo * rel;
      }
      previous_truth = truth;
      KeyframeInput in;
      in.id = i;
      in.utime = 1000000 + i * 2000000;
      in.pose = odo;  // raw odometry (correction_id 0): no correction adopted
      in.cloud = viewFrom(scene, truth.translation(), a + M_PI / 2, 20.0, 0.02, 100 + i);
      closer->addKeyframe(in);
      EXPECT_LE(closer->cachedFeatures(), static_cast<size_t>(cache));
    }
    return closer;
  };
  const auto one = run(1), all = run(1000);
  ASSERT_GE(all->loops().size(), 1u);
  ASSERT_EQ(one->loops().size(), all->loops().size());
  for (size_t i = 0; i < all->loops().size(); ++i) {
    EXPECT_EQ(one->loops()[i].from_id, all->loops()[i].from_id);
    EXPECT_EQ(one->loops()[i].to_id, all->loops()[i].to_id);
    EXPECT_TRUE(one->loops()[i].T_to_from.matrix() == all->loops()[i].T_to_from.matrix()) << i;
  }
  for (const auto& [id, pose] : all->graph().poses())
    EXPECT_TRUE(one->graph().poses().at(id).matrix() == pose.matrix()) << id;
  EXPECT_EQ(one->storedCloudBytes(), all->storedCloudBytes());
  for (int id : {0, 17, total - 1}) {
    const Points a = one->mapCloud(id), b = all->mapCloud(id);
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) ASSERT_TRUE(a[i] == b[i]);
  }
}

// Features are derived only where a registration might be tried: on the first lap no node older
// than exclude_recent_s (15 keyframes) is within search_radius (12 m) until the lap nearly closes
// (keyframe 31 of 36 on the 14 m circle), so until then no keyframe's features are derived; then
// the loops are found.
TEST(LoopCloser, FeaturesAreDerivedOnlyWhereAnOlderNodeIsNear) {
  const Points scene = makeScene(41, 0.15);
  const int per_lap = 36, total = per_lap + 6;
  LoopCloserOptions o;
  o.odometry_translation_per_m = 0.02;
  o.odometry_rotation_per_m = 2.5e-3;
  LoopCloser closer(o);
  int first_derived = -1;
  for (int i = 0; i < total; ++i) {
    const double a = 2 * M_PI * i / per_lap;
    const Pose3 truth = yawPose(a + M_PI / 2, Vec3(14 * std::cos(a), 14 * std::sin(a), 1.8));
    KeyframeInput in;
    in.id = i;
    in.utime = 1000000 + i * 2000000;
    in.pose = truth;
    in.cloud = viewFrom(scene, truth.translation(), a + M_PI / 2, 20.0, 0.02, 100 + i);
    closer.addKeyframe(in);
    if (first_derived < 0 && closer.cachedFeatures() > 0) first_derived = i;
  }
  std::printf("[lazy] features first derived at keyframe %d of %d; %lld registrations, %lld rejected\n", first_derived,
              total, static_cast<long long>(closer.registrations()),
              static_cast<long long>(closer.rejectedRegistrations().total()));
  EXPECT_GE(first_derived, 30);
  EXPECT_GE(closer.loops().size(), 1u);
  // every candidate registered is counted: accepted (a loop, or refused by the consistency check)
  // or rejected by the registration's own tests
  EXPECT_EQ(closer.registrations(), static_cast<int64_t>(closer.loops().size() + closer.refusedLoops().size()) +
                                        closer.rejectedRegistrations().total());
}

// Exact odometry around a loop and past the start: the loops are verified and kept in the graph,
// but the estimate already satisfies them, so nothing is optimised or published; with the gate at
// zero the same loops each publish a correction.
TEST(LoopCloser, LoopsTheEstimateAlreadySatisfiesAreKeptWithoutACorrection) {
  const Points scene = makeScene(41, 0.15);
  const int per_lap = 36, total = per_lap + 6;
  auto run = [&](double min_translation, double min_rotation) {
    LoopCloserOptions o;
    o.min_correction_translation = min_translation;
    o.min_correction_rotation = min_rotation;
    auto closer = std::make_unique<LoopCloser>(o);
    int published = 0;
    for (int i = 0; i < total; ++i) {
      const double a = 2 * M_PI * i / per_lap;
      KeyframeInput in;
      in.id = i;
      in.utime = 1000000 + i * 2000000;
      in.pose = yawPose(a + M_PI / 2, Vec3(14 * std::cos(a), 14 * std::sin(a), 1.8));
      in.cloud = viewFrom(scene, in.pose.translation(), a + M_PI / 2, 20.0, 0.02, 100 + i);
      const AddResult r = closer->addKeyframe(in);
      EXPECT_EQ(r.correction.has_value(), r.loop.has_value() && r.loop->corrected) << i;
      published += r.correction.has_value();
    }
    EXPECT_EQ(closer->corrections(), static_cast<size_t>(published));
    EXPECT_EQ(closer->graph().numLoops(), closer->loops().size());
    return closer;
  };
  const auto gated = run(0.02, 1.75e-3);
  ASSERT_GE(gated->loops().size(), 2u);
  EXPECT_EQ(gated->corrections(), 0u);
  for (const AcceptedLoop& l : gated->loops()) {
    EXPECT_FALSE(l.corrected);
    EXPECT_LT(l.residual_translation, 0.02);
    EXPECT_LT(l.residual_rotation, 1.75e-3);
  }
  const auto ungated = run(0.0, 0.0);
  ASSERT_EQ(ungated->loops().size(), gated->loops().size());
  EXPECT_EQ(ungated->corrections(), ungated->loops().size());
  for (const AcceptedLoop& l : ungated->loops()) EXPECT_TRUE(l.corrected);
}

// Three laps of the same circle with exact odometry: the keyframes of the second and third laps
// join the first lap's nodes (reduced pose graph), so the graph stays at one lap's nodes while
// every keyframe keeps a pose; with merge_distance 0 every keyframe is a node.
TEST(LoopCloser, KeyframesPassingAgainJoinTheOlderNodes) {
  const Points scene = makeScene(41, 0.15);
  const int per_lap = 36, total = 3 * per_lap;
  auto run = [&](double merge_distance) {
    LoopCloserOptions o;
    o.merge_distance = merge_distance;
    o.candidates.exclude_recent_s = 20.0;
    auto closer = std::make_unique<LoopCloser>(o);
    std::vector<Pose3> truth;
    for (int i = 0; i < total; ++i) {
      const double a = 2 * M_PI * i / per_lap;
      KeyframeInput in;
      in.id = i;
      in.utime = 1000000 + i * 2000000;
      // a little off the first lap's path, so that joining is a registration, not an identity
      const double r = 14.0 + 0.3 * (i / per_lap);
      in.pose = yawPose(a + M_PI / 2, Vec3(r * std::cos(a), r * std::sin(a), 1.8));
      in.cloud = viewFrom(scene, in.pose.translation(), a + M_PI / 2, 20.0, 0.02, 100 + i);
      truth.push_back(in.pose);
      closer->addKeyframe(in);
    }
    EXPECT_EQ(closer->size(), static_cast<size_t>(total));
    double worst = 0.0;
    closer->forEachPose([&](int64_t id, const Pose3& T) { worst = std::max(worst, translationError(T, truth[id])); });
    EXPECT_LT(worst, 0.05);
    return closer;
  };
  const auto reduced = run(2.0);
  EXPECT_LE(reduced->graph().poses().size(), static_cast<size_t>(per_lap + 4));
  size_t merged = 0;
  for (const AcceptedLoop& l : reduced->loops()) merged += l.merged;
  EXPECT_GE(merged, static_cast<size_t>(per_lap));
  int own_nodes = 0;  // keyframes of the later laps that became nodes (a registration that failed)
  for (int id = per_lap + 2; id < total; ++id) own_nodes += reduced->node(id) >= per_lap;
  EXPECT_LE(own_nodes, 4);
  const auto full = run(0.0);
  EXPECT_EQ(full->graph().poses().size(), static_cast<size_t>(total));
}

TEST(LoopNode, EmptyAndInconsistentCloudsDoNotCrash) {
  lcm::LCM lcm("memq://");
  LoopNode node(lcm, quietNode("loop"), {});
  keyframe_t empty = makeKeyframe(0, Pose3::Identity(), {});
  lcm.publish("KEYFRAME", &empty);
  keyframe_t nan_points = makeKeyframe(1, Pose3::Identity(), {Vec3(std::nan(""), 0, 0), Vec3(1, 2, 3)});
  lcm.publish("KEYFRAME", &nan_points);
  drain(lcm);
  EXPECT_EQ(node.closer().size(), 2u);
}

}  // namespace
}  // namespace livo::loop
