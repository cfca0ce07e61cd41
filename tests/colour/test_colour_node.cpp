// livo-colour's node on LCM's in-process memq:// provider: scans, odometry and images in,
// COLORED_CLOUD out, map files on finish, bad input refused without a crash.
#include <array>
#include <cmath>
#include <filesystem>
#include <set>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "livo/colored_cloud_t.hpp"
#include "livo/colour/colour_node.hpp"
#include "livo/coloured_point_files.hpp"
#include "livo/image_t.hpp"
#include "livo/keyframe_t.hpp"
#include "livo/loop_correction_t.hpp"
#include "livo/messages.hpp"
#include "livo/odometry_t.hpp"
#include "livo/registered_scan_t.hpp"
#include "scene_fixtures.hpp"
#include "temp_path.hpp"

using namespace livo;
using livo_test::WallAndBox;

namespace {

void drain(lcm::LCM& lcm) {
  while (lcm.handleTimeout(0) > 0) {
  }
}

/// num_points and the per-point fields of a cloud whose x, y, z are set: no intensity, every point
/// stamped mid-sweep, no ring.
void fillPerPointFields(point_cloud_t* c) {
  c->num_points = static_cast<int32_t>(c->x.size());
  c->intensity.assign(c->x.size(), 0.f);
  c->time_offset.assign(c->x.size(), 0.05f);
  c->ring.assign(c->x.size(), -1);
}

registered_scan_t makeScan(int64_t utime) {
  registered_scan_t s{};
  s.utime = utime;
  s.orientation[0] = 1.0;
  point_cloud_t& c = s.cloud;
  c.utime = utime - 100000;
  c.frame = "W";
  c.sweep_duration = 0.1f;
  WallAndBox::points(0.05, 0.1, &c.x, &c.y, &c.z);
  fillPerPointFields(&c);
  return s;
}

image_t makeImage(const CameraRig& rig, int64_t utime) {
  const colour::ColourImage img = WallAndBox::render(rig, utime);
  image_t m{};
  m.utime = utime;
  m.frame = "C";
  m.width = rig.width;
  m.height = rig.height;
  m.row_stride = rig.width;
  m.encoding = image_t::ENCODING_GRAY8;
  m.data.assign(img.pixels.datastart, img.pixels.dataend);
  m.size = static_cast<int32_t>(m.data.size());
  return m;
}

/// A colour node on `lcm` with the test camera, a 0.1 s time window, quiet, no HEALTH.
struct TestNode {
  SensorRig rig;
  colour::ColourNode node;
  TestNode(lcm::LCM& lcm, const std::string& dir, int max_points_per_message = 65536)
      : rig(withCamera()), node(lcm, quiet(), options(max_points_per_message), rig, dir) {}
  static SensorRig withCamera() {
    SensorRig r;
    r.camera = livo_test::testCamera(false);
    return r;
  }
  static colour::ColourNodeOptions options(int max_points_per_message) {
    colour::ColourNodeOptions o;
    o.core.max_time_difference = 0.1;
    o.max_points_per_message = max_points_per_message;
    return o;
  }
  static NodeOptions quiet() {
    NodeOptions n;
    n.name = "colour";
    n.quiet = true;
    n.health_period_s = 0;
    return n;
  }
};

/// The body at the origin, at 0.9 .. 1.2 s.
void publishStillOdometry(lcm::LCM& lcm) {
  odometry_t odo{};
  odo.orientation[0] = 1.0;
  for (int64_t utime : {900000, 1000000, 1100000, 1200000}) {
    odo.utime = utime;
    lcm.publish("ODOMETRY", &odo);
  }
}

/// Every COLORED_CLOUD message, appended to `out`.
void collect(lcm::LCM& lcm, std::vector<colored_cloud_t>* out) {
  lcm.subscribeFunction<colored_cloud_t, std::vector<colored_cloud_t>*>(
      "COLORED_CLOUD",
      [](const lcm::ReceiveBuffer*, const std::string&, const colored_cloud_t* m, std::vector<colored_cloud_t>* o) {
        o->push_back(*m);
      },
      out);
}

/// Keyframe 0 at the origin, the body still there, one image and the two scans that colour it.
void colourTheRoomAtKeyframe0(lcm::LCM& lcm, const CameraRig& camera) {
  keyframe_t kf{};
  kf.id = 0;
  kf.utime = 1000000;
  kf.orientation[0] = 1.0;
  kf.cloud.frame = "I";
  lcm.publish("KEYFRAME", &kf);
  publishStillOdometry(lcm);
  const image_t img = makeImage(camera, 1050000);
  lcm.publish("CAMERA", &img);
  for (int64_t utime : {1100000, 1200000}) {
    const registered_scan_t scan = makeScan(utime);
    lcm.publish("REGISTERED_SCAN", &scan);
  }
  drain(lcm);
}

/// Correction 1 at 1.3 s (the identity but for keyframe 0): keyframe 0 at 0.5 m along x with
/// `orientation` (w, x, y, z).
loop_correction_t keyframe0Moved(const std::vector<double>& orientation) {
  loop_correction_t c{};
  c.utime = 1300000;
  c.correction_id = 1;
  c.correction_orientation[0] = 1.0;
  c.odometry_to_corrected_orientation[0] = 1.0;
  c.num_keyframes = 1;
  c.keyframe_id = {0};
  c.position = {{0.5, 0.0, 0.0}};
  c.orientation = {orientation};
  return c;
}

}  // namespace

TEST(ColourNode, ColoursScansPublishesAndWritesFiles) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  TestNode t(lcm, livo_test::tempPath("colour_out"));
  colour::ColourNode& node = t.node;
  const SensorRig& rig = t.rig;
  std::vector<colored_cloud_t> received;
  collect(lcm, &received);

  publishStillOdometry(lcm);
  const image_t img = makeImage(*rig.camera, 1050000);
  lcm.publish("CAMERA", &img);
  const registered_scan_t scan = makeScan(1100000);
  lcm.publish("REGISTERED_SCAN", &scan);
  drain(lcm);
  EXPECT_EQ(node.pipeline().stats().images, 0);  // waits for a scan ending after 1.05 + 0.1 s
  const registered_scan_t next = makeScan(1200000);
  lcm.publish("REGISTERED_SCAN", &next);
  drain(lcm);
  EXPECT_EQ(node.pipeline().stats().images, 1);
  ASSERT_GT(received.size(), 0u);
  int64_t published_points = 0;
  for (const colored_cloud_t& m : received) published_points += m.num_points;
  EXPECT_GT(published_points, 2000);

  // bad input: empty cloud, NaN pose, stale scan, undecodable JPEG, wrong frame
  registered_scan_t empty = makeScan(1250000);
  empty.cloud.num_points = 0;
  empty.cloud.x.clear(), empty.cloud.y.clear(), empty.cloud.z.clear();
  empty.cloud.intensity.clear(), empty.cloud.time_offset.clear(), empty.cloud.ring.clear();
  lcm.publish("REGISTERED_SCAN", &empty);
  registered_scan_t nan_pose = makeScan(1300000);
  nan_pose.position[0] = NAN;
  lcm.publish("REGISTERED_SCAN", &nan_pose);
  lcm.publish("REGISTERED_SCAN", &scan);  // same stamp again
  registered_scan_t body = makeScan(1400000);
  body.cloud.frame = "I";
  lcm.publish("REGISTERED_SCAN", &body);
  image_t junk = img;
  junk.utime = 1250000;
  junk.encoding = image_t::ENCODING_JPEG;
  junk.data.assign(64, 0x11);
  junk.size = 64;
  lcm.publish("CAMERA", &junk);
  drain(lcm);
  EXPECT_EQ(node.pipeline().stats().scans, 2);

  node.finish();
  ColouredPoints back;
  std::string error;
  ASSERT_TRUE(readPly(node.plyPath(), &back, &error)) << error;
  EXPECT_EQ(back.size(), node.pipeline().map().colouredCount());
  ASSERT_TRUE(readPcd(node.pcdPath(), &back, &error)) << error;
  EXPECT_EQ(back.size(), node.pipeline().map().colouredCount());
}

// KEYFRAME and LOOP_CORRECTION over the bus: the points anchored to a corrected keyframe move with
// it and are published again on COLORED_CLOUD at their new positions; a malformed correction is
// refused and moves nothing.
TEST(ColourNode, LoopCorrectionMovesAndRepublishesTheKeyframesPoints) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  TestNode t(lcm, livo_test::tempPath("colour_loop"));
  colour::ColourNode& node = t.node;
  std::vector<colored_cloud_t> received;
  collect(lcm, &received);

  colourTheRoomAtKeyframe0(lcm, *t.rig.camera);
  const size_t coloured = node.pipeline().map().colouredCount();
  ASSERT_GT(coloured, 1000u);
  std::vector<Eigen::Vector3f> before;
  for (const auto& p : node.pipeline().map().points()) before.push_back(p.position);
  const size_t messages = received.size();

  const loop_correction_t bad = keyframe0Moved({NAN, 0.0, 0.0, 0.0});
  lcm.publish("LOOP_CORRECTION", &bad);
  drain(lcm);
  EXPECT_EQ(received.size(), messages);
  EXPECT_EQ(node.pipeline().map().points()[0].position, before[0]);

  const loop_correction_t good = keyframe0Moved({1.0, 0.0, 0.0, 0.0});  // keyframe 0 was 0.5 m further along x
  lcm.publish("LOOP_CORRECTION", &good);
  drain(lcm);
  ASSERT_EQ(received.size(), messages + 1);
  const colored_cloud_t& moved = received.back();
  EXPECT_EQ(moved.utime, 1300000);
  EXPECT_EQ(static_cast<size_t>(moved.num_points), node.pipeline().map().colouredCount());
  EXPECT_GT(static_cast<size_t>(moved.num_points), coloured / 2);  // a few merge into shared voxels
  // each published point is a point of the map before the correction, moved by +0.5 m in x
  auto cell = [](const Eigen::Vector3f& p) {
    return std::array<long, 3>{std::lround(p.x() * 100), std::lround(p.y() * 100), std::lround(p.z() * 100)};
  };
  std::set<std::array<long, 3>> shifted;
  for (const Eigen::Vector3f& b : before) shifted.insert(cell(b + Eigen::Vector3f(0.5f, 0.f, 0.f)));
  int found = 0;
  for (int i = 0; i < moved.num_points; ++i) found += shifted.count(cell({moved.x[i], moved.y[i], moved.z[i]})) ? 1 : 0;
  EXPECT_EQ(found, moved.num_points);
}

// A correction that moves the whole map is published in messages of at most
// max_points_per_message points, which together carry every moved point once.
TEST(ColourNode, SplitsLargeUpdatesIntoBoundedMessages) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  constexpr int kMaxPoints = 300;
  TestNode t(lcm, livo_test::tempPath("colour_chunks"), kMaxPoints);
  std::vector<colored_cloud_t> received;
  collect(lcm, &received);
  colourTheRoomAtKeyframe0(lcm, *t.rig.camera);
  const size_t coloured = t.node.pipeline().map().colouredCount();
  ASSERT_GT(coloured, 3u * kMaxPoints);
  for (const colored_cloud_t& m : received) EXPECT_LE(m.num_points, kMaxPoints);
  received.clear();

  const loop_correction_t move = keyframe0Moved({1.0, 0.0, 0.0, 0.0});
  lcm.publish("LOOP_CORRECTION", &move);
  drain(lcm);
  const size_t moved = t.node.pipeline().map().colouredCount();  // a few merge into shared voxels
  EXPECT_GT(moved, coloured / 2);
  EXPECT_EQ(received.size(), (moved + kMaxPoints - 1) / kMaxPoints);
  size_t total = 0;
  std::set<std::array<float, 3>> distinct;
  for (const colored_cloud_t& m : received) {
    EXPECT_EQ(m.utime, 1300000);
    EXPECT_LE(m.num_points, kMaxPoints);
    EXPECT_GT(m.num_points, 0);
    total += static_cast<size_t>(m.num_points);
    for (int i = 0; i < m.num_points; ++i) distinct.insert({m.x[i], m.y[i], m.z[i]});
  }
  EXPECT_EQ(total, moved);
  EXPECT_EQ(distinct.size(), total);
}

namespace {
/// A few world-frame points around `at` (a marker to find in the map), published in (epoch,
/// correction) with the body at `body`.
registered_scan_t markerScan(int64_t utime, const Eigen::Vector3f& at, const Vec3& body, int32_t epoch,
                             int64_t correction_id) {
  registered_scan_t s = makeScan(utime);
  s.position[0] = body.x(), s.position[1] = body.y(), s.position[2] = body.z();
  s.epoch = epoch;
  s.correction_id = correction_id;
  point_cloud_t& c = s.cloud;
  c.x.clear(), c.y.clear(), c.z.clear();
  for (int i = 0; i < 5; ++i) {
    c.x.push_back(at.x() + 0.01f * i);
    c.y.push_back(at.y());
    c.z.push_back(at.z());
  }
  fillPerPointFields(&c);
  return s;
}

bool mapHasPointNear(const colour::ColouringPipeline& p, const Eigen::Vector3f& at) {
  for (const auto& point : p.map().points())
    if ((point.position - at).norm() < 0.1f) return true;
  return false;
}

int64_t rejectedOn(colour::ColourNode& node, const std::string& channel) {
  for (const channel_stats_t& c : node.node().healthMessage().channels)
    if (c.channel == channel) return c.rejected;
  return -1;
}
}  // namespace

// Real-time hand-offs (lcmtypes/loop_correction_t.lcm): after correction 1 moved the map, a scan
// lio published before adopting it (correction_id 0) is moved onto it, one published after (1) is
// used as it is (not corrected twice), one in a correction never received is refused. A scan of a
// new odometry epoch writes the old map as <map_name>_epoch0.ply/.pcd and starts an empty one; the
// old epoch's scans and corrections are refused afterwards.
TEST(ColourNode, LateScansJoinTheCorrectedMapAndANewEpochStartsANewMap) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  const std::string dir = livo_test::tempPath("colour_epochs");
  TestNode t(lcm, dir);
  colour::ColourNode& node = t.node;
  std::vector<colored_cloud_t> received;
  collect(lcm, &received);

  colourTheRoomAtKeyframe0(lcm, *t.rig.camera);
  ASSERT_GT(node.pipeline().map().colouredCount(), 1000u);

  // correction 1: the odometry frame moves 0.5 m along x
  Pose3 T = Pose3::Identity();
  T.translation() = Vec3(0.5, 0.0, 0.0);
  loop_correction_t c1{};
  c1.utime = 1250000;
  c1.correction_id = 1;
  poseTo(T, c1.correction_position, c1.correction_orientation);
  poseTo(T, c1.odometry_to_corrected_position, c1.odometry_to_corrected_orientation);
  c1.num_keyframes = 1;
  c1.keyframe_id = {0};
  c1.position = {{0.5, 0.0, 0.0}};
  c1.orientation = {{1.0, 0.0, 0.0, 0.0}};
  lcm.publish("LOOP_CORRECTION", &c1);
  drain(lcm);
  const size_t published = received.size();
  ASSERT_GT(published, 0u);
  EXPECT_EQ(received.back().utime, 1250000);  // the moved map republished

  const Eigen::Vector3f a(1.0f, 2.0f, 0.3f), b(1.0f, 3.0f, 0.3f), c(1.0f, 4.0f, 0.3f), shift(0.5f, 0.f, 0.f);
  const registered_scan_t late = markerScan(1300000, a, Vec3::Zero(), 0, 0);  // before lio adopted 1
  lcm.publish("REGISTERED_SCAN", &late);
  const registered_scan_t adopted = markerScan(1400000, b + shift, Vec3(0.5, 0.0, 0.0), 0, 1);  // after
  lcm.publish("REGISTERED_SCAN", &adopted);
  const registered_scan_t unknown = markerScan(1450000, c, Vec3::Zero(), 0, 7);  // never received here
  lcm.publish("REGISTERED_SCAN", &unknown);
  drain(lcm);
  EXPECT_TRUE(mapHasPointNear(node.pipeline(), a + shift));
  EXPECT_FALSE(mapHasPointNear(node.pipeline(), a));
  EXPECT_TRUE(mapHasPointNear(node.pipeline(), b + shift));
  EXPECT_FALSE(mapHasPointNear(node.pipeline(), b + 2 * shift));  // not corrected twice
  EXPECT_FALSE(mapHasPointNear(node.pipeline(), c));
  EXPECT_FALSE(mapHasPointNear(node.pipeline(), c + shift));
  EXPECT_EQ(rejectedOn(node, "REGISTERED_SCAN"), 1);
  const size_t coloured_epoch0 = node.pipeline().map().colouredCount();

  // lio reset: epoch 1, its clock behind the old one
  registered_scan_t reset = makeScan(500000);
  reset.epoch = 1;
  lcm.publish("REGISTERED_SCAN", &reset);
  drain(lcm);
  EXPECT_EQ(node.pipeline().stats().scans, 1);
  EXPECT_EQ(node.pipeline().map().colouredCount(), 0u);
  EXPECT_GT(node.pipeline().map().size(), 1000u);
  EXPECT_FALSE(mapHasPointNear(node.pipeline(), a + shift));
  ColouredPoints old;
  std::string error;
  ASSERT_TRUE(readPly(dir + "/colour_map_epoch0.ply", &old, &error)) << error;
  EXPECT_EQ(old.size(), coloured_epoch0);
  ASSERT_TRUE(readPcd(dir + "/colour_map_epoch0.pcd", &old, &error)) << error;
  EXPECT_EQ(old.size(), coloured_epoch0);

  // the old epoch afterwards: a scan and a correction, both without effect
  const size_t before = received.size();
  const registered_scan_t stale = markerScan(1500000, a, Vec3::Zero(), 0, 1);
  lcm.publish("REGISTERED_SCAN", &stale);
  loop_correction_t c2 = c1;
  c2.utime = 1550000;
  c2.correction_id = 2;
  c2.previous_correction_id = 1;
  lcm.publish("LOOP_CORRECTION", &c2);
  drain(lcm);
  EXPECT_EQ(rejectedOn(node, "REGISTERED_SCAN"), 2);
  EXPECT_EQ(node.pipeline().stats().scans, 1);
  EXPECT_EQ(received.size(), before);
  EXPECT_FALSE(mapHasPointNear(node.pipeline(), a));
}

TEST(ColourNode, RefusesARigWithoutCamera) {
  lcm::LCM lcm("memq://");
  SensorRig rig;
  NodeOptions node_options;
  node_options.name = "colour";
  node_options.quiet = true;
  EXPECT_THROW(colour::ColourNode(lcm, node_options, colour::ColourNodeOptions{}, rig, "."), ConfigError);
}

// livo-colour reads the rig before it opens LCM (so --check-config refuses a rig without camera too).
TEST(ColourConfig, RigMustHaveACamera) {
  const std::string imu =
      "rig:\n  imu: {rate_hz: 200, gyro_noise_density: 0, gyro_random_walk: 0, accel_noise_density: 0, "
      "accel_random_walk: 0}\n";
  try {
    colour::readColourRig(Config::fromString(imu, "nocam.yaml"));
    ADD_FAILURE() << "a rig without camera is refused";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("nocam.yaml: rig.camera: livo-colour needs a camera"), std::string::npos)
        << e.what();
  }
  const std::string camera =
      "  camera: {width: 640, height: 480, fx: 400, fy: 400, cx: 319.5, cy: 239.5, rate_hz: 20, "
      "T_I_C: {translation: [0, 0, 0], rpy_deg: [-90, 0, -90]}}\n";
  EXPECT_EQ(colour::readColourRig(Config::fromString(imu + camera)).camera->width, 640);
}

TEST(ColourConfig, ReadsKeysStrictly) {
  const Config ok = Config::fromString("colour: {voxel_size: 0.1, vignetting: 0.25, map_name: room}");
  const colour::ColourNodeOptions o = colour::readColourNodeOptions(ok);
  EXPECT_DOUBLE_EQ(o.core.voxel_size, 0.1);
  EXPECT_DOUBLE_EQ(o.core.vignetting, 0.25);
  EXPECT_EQ(o.map_name, "room");
  EXPECT_THROW(colour::readColourNodeOptions(Config::fromString("colour: {voxel_sise: 0.1}")), ConfigError);
  EXPECT_THROW(colour::readColourNodeOptions(Config::fromString("colour: {voxel_size: -1}")), ConfigError);
  EXPECT_EQ(
      colour::readColourNodeOptions(Config::fromString("colour: {max_pending_images: 8}")).core.max_pending_images, 8);
  EXPECT_THROW(colour::readColourNodeOptions(Config::fromString("colour: {max_pending_images: 0}")), ConfigError);
}
