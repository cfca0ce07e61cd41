// livo-vio-feature's core without LCM: VioFeatureEstimator fed directly with the simulated room
// (rendered grey images at 20 Hz, the trajectory's exact IMU at 200 Hz) follows the truth; an IMU
// gap restarts it in a new epoch with the tracker started over.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "livo/config.hpp"
#include "livo/so3.hpp"
#include "livo/vio_feature/vio_feature_config.hpp"
#include "livo/vio_feature/vio_feature_estimator.hpp"
#include "rendered_sequence.hpp"

using namespace livo;
using namespace livo::vio_feature;

namespace {

/// The room's core options (config/sim/room.yaml: a grey camera, no wheels), without LiDAR depth.
VioFeatureOptions roomOptions() {
  VioFeatureOptions o =
      readVioFeatureNodeOptions(Config::load(std::string(LIVO_SOURCE_DIR) + "/config/sim/room.yaml")).core;
  o.use_lidar_depth = false;  // no LIO here
  return o;
}

/// Feeds the IMU from sample *k on (200 Hz) until it has passed trajectory time t, skipping the
/// samples inside (gap_from, gap_to).
void feedImuUpTo(const livo_test::RenderedSequence& seq, double t, int* k, VioFeatureEstimator* e,
                 double gap_from = 1e9, double gap_to = 1e9) {
  while (true) {
    const double ti = 0.005 * *k;
    ++*k;
    if (ti > gap_from && ti < gap_to) continue;
    EXPECT_TRUE(e->addImu(livo_test::exactImu(seq, ti)));
    if (seq.utime(ti) >= e->imuTime(seq.utime(t))) return;
  }
}

}  // namespace

TEST(VioFeatureEstimator, FollowsTheRenderedRoomWithoutLcm) {
  const livo_test::RenderedSequence seq("config/sim/room.yaml");
  const VioFeatureOptions options = roomOptions();
  ASSERT_FALSE(options.use_depth_image);
  ASSERT_FALSE(options.window.use_wheel);
  VioFeatureEstimator e(options);
  struct Estimate {
    double t;
    Pose3 pose;
  };
  std::vector<Estimate> states;
  int imu_k = 0, images = 0, first_state_image = -1;
  const double duration = 8.0;  // 2 s at rest (the start), then walking
  for (double t = 0.05; t <= duration; t += 0.05) {
    feedImuUpTo(seq, t, &imu_k, &e);
    ImageInput in;
    in.utime = seq.utime(t);
    in.grey = seq.image(t);
    const ImageOutcome out = e.addImage(in);
    ++images;
    EXPECT_FALSE(out.restarted) << t;
    EXPECT_FALSE(out.with_depth_image);
    EXPECT_FALSE(out.with_lidar);
    EXPECT_EQ(out.epoch, 0);
    if (!out.hasState()) continue;
    if (states.empty()) {
      EXPECT_EQ(out.frame.status, FrameResult::Status::kInitialized);
      first_state_image = images;
    }
    EXPECT_EQ(out.frame.state.utime, e.imuTime(in.utime));
    states.push_back({t, out.frame.state.pose});
  }
  EXPECT_EQ(e.stats().images, images);
  EXPECT_EQ(e.stats().tracked, static_cast<int64_t>(states.size()));
  EXPECT_EQ(e.epoch(), 0);
  // initialised within the first second of rest (measured: at 0.45 s), a state for every image
  // from then on
  ASSERT_GT(states.size(), 140u);
  EXPECT_LT(states.front().t, 1.0);
  EXPECT_EQ(static_cast<int>(states.size()), images - first_state_image + 1);
  // against the truth, both taken relative to the first state (V's origin and yaw are the
  // estimator's own)
  const Pose3 T0 = states.front().pose;
  const Pose3 G0 = seq.trajectory().at(states.front().t).T_W_I;
  double worst_position = 0.0, worst_rotation_deg = 0.0, distance = 0.0;
  Vec3 prev = G0.translation();
  for (const Estimate& s : states) {
    const Pose3 G = seq.trajectory().at(s.t).T_W_I;
    const Pose3 rel_est = T0.inverse() * s.pose;
    const Pose3 rel_true = G0.inverse() * G;
    worst_position = std::max(worst_position, (rel_est.translation() - rel_true.translation()).norm());
    const double angle = so3::Log(Mat3(rel_true.linear().transpose() * rel_est.linear())).norm();
    worst_rotation_deg = std::max(worst_rotation_deg, angle * 180.0 / M_PI);
    distance += (G.translation() - prev).norm();
    prev = G.translation();
  }
  std::cout << states.size() << " states of " << images << " images over " << distance << " m: worst position error "
            << worst_position << " m, worst rotation error " << worst_rotation_deg << " deg\n";
  // measured: 152 states over 4.69 m, worst 0.023 m and 0.25 deg
  EXPECT_GT(distance, 3.0);
  EXPECT_LT(worst_position, 0.035);
  EXPECT_LT(worst_rotation_deg, 0.4);
}

TEST(VioFeatureEstimator, AnImuGapStartsANewEpoch) {
  const livo_test::RenderedSequence seq("config/sim/room.yaml");
  const VioFeatureOptions options = roomOptions();
  VioFeatureEstimator e(options);
  int imu_k = 0;
  const double gap_from = 1.5, gap_to = 1.5 + 2.0 * options.window.max_imu_gap_s;
  bool tracking = false;
  for (double t = 0.05; t <= 1.5 + 1e-9; t += 0.05) {
    feedImuUpTo(seq, t, &imu_k, &e);
    ImageInput in;
    in.utime = seq.utime(t);
    in.grey = seq.image(t);
    tracking = e.addImage(in).hasState();
  }
  ASSERT_TRUE(tracking);  // initialised at rest
  ASSERT_TRUE(e.window().initialized());
  // no IMU for twice max_imu_gap_s, then an image
  const double t = gap_to + 0.01;
  feedImuUpTo(seq, t, &imu_k, &e, gap_from, gap_to);
  ImageInput in;
  in.utime = seq.utime(t);
  in.grey = seq.image(t);
  const ImageOutcome out = e.addImage(in);
  EXPECT_TRUE(out.restarted);
  EXPECT_FALSE(out.hasState());
  EXPECT_FALSE(out.frame.note.empty());
  EXPECT_EQ(out.epoch, 1);
  EXPECT_EQ(e.epoch(), 1);
  EXPECT_FALSE(e.window().initialized());
  EXPECT_EQ(e.lastImageTime(), e.imuTime(in.utime));
}
