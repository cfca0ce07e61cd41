// The livo-vio-feature node on LCM's in-process memq:// provider, fed with the simulated room
// (rendered images, the trajectory's exact IMU): VISUAL_STATE and VISUAL_ODOMETRY follow the truth;
// the output does not depend on how the channels interleave; bad images and malformed messages are
// refused without stopping it; the config section is strict.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>

#include "bus_messages.hpp"
#include "livo/image_t.hpp"
#include "livo/imu_t.hpp"
#include "livo/messages.hpp"
#include "livo/odometry_t.hpp"
#include "livo/vio_feature/vio_feature_node.hpp"
#include "livo/visual_state_t.hpp"
#include "rendered_sequence.hpp"

using namespace livo;
using namespace livo::vio_feature;

namespace {

using livo_test::encode;
using livo_test::Message;

/// The room's first `duration` s (2 s at rest, then walking): IMU at 200 Hz from the trajectory's
/// exact motion, grey images at 20 Hz; `image_lag_us` delays the images' place in the stream.
std::vector<Message> roomMessages(const livo_test::RenderedSequence& seq, const sim::BodyTrajectory& traj,
                                  double duration, int64_t image_lag_us) {
  std::vector<Message> out;
  for (double t = 0.0; t <= duration + 0.2; t += 0.005) {
    const sim::BodyState s = traj.at(t);
    imu_t m;
    m.utime = seq.utime(t);
    vec3To(s.angular_velocity, m.angular_velocity);
    vec3To(Vec3(s.T_W_I.linear().transpose() * (s.acceleration + Vec3(0.0, 0.0, 9.81))), m.linear_acceleration);
    out.push_back(encode(m.utime, "IMU", m));
  }
  for (double t = 0.05; t <= duration; t += 0.05) {
    const cv::Mat grey = seq.image(t);
    image_t m;
    m.utime = seq.utime(t);
    m.frame = "C";
    m.width = grey.cols;
    m.height = grey.rows;
    m.row_stride = grey.cols;
    m.encoding = image_t::ENCODING_GRAY8;
    m.exposure_time = 0.005f;
    m.size = grey.cols * grey.rows;
    m.data.assign(grey.data, grey.data + m.size);
    out.push_back(encode(m.utime + image_lag_us, "CAMERA", m));
  }
  return out;
}

struct Outputs {
  std::vector<visual_state_t> states;
  std::vector<odometry_t> odometry;
  int64_t camera_rejected = 0;
  VioFeatureNode::Counts counts;
};

Outputs runNode(std::vector<Message> messages, const VioFeatureNodeOptions& options) {
  livo_test::sortByArrival(&messages);
  lcm::LCM lcm("memq://");
  EXPECT_TRUE(lcm.good());
  NodeOptions node_options;
  node_options.name = "vio_feature";
  node_options.health_period_s = 0.0;
  node_options.quiet = true;
  VioFeatureNode node(lcm, node_options, options);
  Node observer(lcm, NodeOptions{"observer", "PROGRESS_OBS", "HEALTH_OBS", 0.0, false, true, {}});
  Outputs out;
  observer.subscribe<visual_state_t>("VISUAL_STATE", [&](const visual_state_t& m) { out.states.push_back(m); });
  observer.subscribe<odometry_t>("VISUAL_ODOMETRY", [&](const odometry_t& m) { out.odometry.push_back(m); });
  livo_test::publishAll(lcm, messages);
  for (const auto& c : node.node().channelStats())
    if (c.channel == "CAMERA") out.camera_rejected = c.rejected + c.decode_failures;
  out.counts = node.counts();
  return out;
}

VioFeatureNodeOptions roomOptions() {
  VioFeatureNodeOptions o =
      readVioFeatureNodeOptions(Config::load(std::string(LIVO_SOURCE_DIR) + "/config/sim/room.yaml"));
  o.core.use_lidar_depth = false;  // no LIO here
  return o;
}

}  // namespace

TEST(VioFeatureNode, FollowsTheRoomAndDoesNotDependOnTheInterleaving) {
  const livo_test::RenderedSequence seq("config/sim/room.yaml");
  sim::SimOverrides ov;
  ov.duration_s = 30.0;
  const sim::SimulationSetup setup = sim::loadSimulation(std::string(LIVO_SOURCE_DIR) + "/config/sim/room.yaml", ov);
  const double duration = 8.0;
  const Outputs a = runNode(roomMessages(seq, *setup.trajectory, duration, 0), roomOptions());
  // the images 0.3 s late in the stream: processed when they come, with the same result
  const Outputs b = runNode(roomMessages(seq, *setup.trajectory, duration, 300'000), roomOptions());
  ASSERT_GT(a.states.size(), 100u);
  ASSERT_EQ(a.states.size(), a.odometry.size());
  EXPECT_EQ(a.states.front().status, static_cast<int8_t>(visual_state_t::STATUS_INITIALIZED));
  EXPECT_EQ(a.camera_rejected, 0);
  // against the truth, both started at the first state
  const Pose3 T0 = poseFrom(a.states.front().position, a.states.front().orientation);
  const double t_first = static_cast<double>(a.states.front().utime - seq.utime(0.0)) * 1e-6;
  const Pose3 G0 = setup.trajectory->at(t_first).T_W_I;
  double worst = 0.0, distance = 0.0;
  Vec3 prev = G0.translation();
  for (const visual_state_t& s : a.states) {
    const double t = static_cast<double>(s.utime - seq.utime(0.0)) * 1e-6;
    const Pose3 G = setup.trajectory->at(t).T_W_I;
    const Vec3 rel_est = (T0.inverse() * poseFrom(s.position, s.orientation)).translation();
    const Vec3 rel_true = (G0.inverse() * G).translation();
    worst = std::max(worst, (rel_est - rel_true).norm());
    distance += (G.translation() - prev).norm();
    prev = G.translation();
  }
  std::cout << a.states.size() << " states over " << distance << " m, worst position error " << worst << " m\n";
  EXPECT_GT(distance, 3.0);
  EXPECT_LT(worst, 0.05 * distance);
  ASSERT_EQ(a.states.size(), b.states.size());
  for (size_t i = 0; i < a.states.size(); ++i) {
    EXPECT_EQ(a.states[i].utime, b.states[i].utime);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(a.states[i].position[k], b.states[i].position[k]) << i;
  }
}

TEST(VioFeatureNode, RefusesBadImagesAndMalformedMessagesAndGoesOn) {
  const livo_test::RenderedSequence seq("config/sim/room.yaml");
  sim::SimOverrides ov;
  ov.duration_s = 30.0;
  const sim::SimulationSetup setup = sim::loadSimulation(std::string(LIVO_SOURCE_DIR) + "/config/sim/room.yaml", ov);
  std::vector<Message> messages = roomMessages(seq, *setup.trajectory, 4.0, 0);
  image_t small;
  small.utime = seq.utime(3.01);
  small.width = 20;
  small.height = 10;
  small.row_stride = 20;
  small.encoding = image_t::ENCODING_GRAY8;
  small.size = 200;
  small.data.assign(200, 128);
  messages.push_back(encode(small.utime, "CAMERA", small));
  messages.push_back(Message{seq.utime(3.02), "CAMERA", {1, 2, 3}});  // not an image_t
  imu_t nan;
  nan.utime = seq.utime(3.0025);
  nan.angular_velocity[0] = std::nan("");
  messages.push_back(encode(nan.utime, "IMU", nan));
  const Outputs out = runNode(messages, roomOptions());
  EXPECT_GE(out.camera_rejected, 2);
  EXPECT_GT(out.states.size(), 30u);
  for (const visual_state_t& s : out.states)
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isfinite(s.position[k]));
}

TEST(VioFeatureNode, ReadsTheRigAndAStrictSection) {
  const std::string base = std::string(LIVO_SOURCE_DIR) + "/config/sim/bridge_deck.yaml";
  const VioFeatureNodeOptions o = readVioFeatureNodeOptions(Config::load(base));
  EXPECT_TRUE(o.core.window.use_wheel);
  EXPECT_TRUE(o.core.use_lidar_depth);
  EXPECT_TRUE(o.core.use_depth_image);
  EXPECT_GT(o.core.window.focal, 100.0);
  Config c = Config::load(base);
  EXPECT_THROW(readVioFeatureNodeOptions(Config::fromString(R"(
rig:
  imu: {rate_hz: 200}
  camera: {width: 640, height: 480, fx: 400, fy: 400, cx: 320, cy: 240}
vio_feature: {window_frame: 10}
)")),
               ConfigError);
  EXPECT_THROW(readVioFeatureNodeOptions(Config::fromString(R"(
rig:
  imu: {rate_hz: 200}
  camera: {width: 640, height: 480, fx: 400, fy: 400, cx: 320, cy: 240}
vio_feature: {window_frames: 2}
)")),
               ConfigError);
  EXPECT_THROW(readVioFeatureNodeOptions(Config::fromString(R"(
rig:
  imu: {rate_hz: 200}
)")),
               ConfigError);
}

TEST(VioFeatureNode, ReadsTheTyreScalesSigma) {
  // bridge_deck.yaml (a rig with wheels, no vio_feature: section) with one appended
  std::ifstream in(std::string(LIVO_SOURCE_DIR) + "/config/sim/bridge_deck.yaml");
  const std::string rig((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_FALSE(rig.empty());
  const VioFeatureNodeOptions defaults = readVioFeatureNodeOptions(Config::fromString(rig));
  EXPECT_TRUE(defaults.core.window.use_wheel);
  EXPECT_EQ(defaults.core.window.wheel_scale_std, 0.02);  // it has a depth image
  // without a depth source the tyres stay nominal unless asked for
  EXPECT_EQ(
      readVioFeatureNodeOptions(Config::fromString(rig + "vio_feature: {depth_image: false, lidar_depth: false}\n"))
          .core.window.wheel_scale_std,
      0.0);
  EXPECT_EQ(
      readVioFeatureNodeOptions(
          Config::fromString(rig + "vio_feature: {depth_image: false, lidar_depth: false, wheel_scale_std: 0.03}\n"))
          .core.window.wheel_scale_std,
      0.03);
  EXPECT_EQ(readVioFeatureNodeOptions(Config::fromString(rig + "vio_feature: {wheel_scale_std: 0}\n"))
                .core.window.wheel_scale_std,
            0.0);
  EXPECT_EQ(readVioFeatureNodeOptions(Config::fromString(rig + "vio_feature: {wheel_scale_std: 0.05}\n"))
                .core.window.wheel_scale_std,
            0.05);
  EXPECT_THROW(readVioFeatureNodeOptions(Config::fromString(rig + "vio_feature: {wheel_scale_std: -0.01}\n")),
               ConfigError);
  EXPECT_THROW(readVioFeatureNodeOptions(Config::fromString(rig + "vio_feature: {wheel_scale_std: 0.5}\n")),
               ConfigError);
}
