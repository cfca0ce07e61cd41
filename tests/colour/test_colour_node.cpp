// livo-colour's node on LCM's in-process memq:// provider: scans, odometry and images in,
// COLORED_CLOUD out, map files on finish, bad input refused without a crash.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "colour_node.hpp"
#include "livo/colored_cloud_t.hpp"
#include "livo/image_t.hpp"
#include "livo/odometry_t.hpp"
#include "livo/registered_scan_t.hpp"
#include "map_files.hpp"
#include "scene_fixtures.hpp"
#include "temp_path.hpp"

using namespace livo;
using livo_test::WallAndBox;

namespace {

void drain(lcm::LCM& lcm) {
  while (lcm.handleTimeout(0) > 0) {
  }
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
  c.num_points = static_cast<int32_t>(c.x.size());
  c.intensity.assign(c.x.size(), 0.f);
  c.time_offset.assign(c.x.size(), 0.05f);
  c.ring.assign(c.x.size(), -1);
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

}  // namespace

TEST(ColourNode, ColoursScansPublishesAndWritesFiles) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  SensorRig rig;
  rig.camera = livo_test::testCamera(false);
  colour::ColourNodeOptions options;
  options.core.max_time_difference = 0.1;
  NodeOptions node_options;
  node_options.name = "colour";
  node_options.quiet = true;
  node_options.health_period_s = 0;
  const std::string dir = livo_test::tempPath("colour_out");
  colour::ColourNode node(lcm, node_options, options, rig, dir);

  int64_t published_points = 0, messages = 0;
  auto* sub = lcm.subscribeFunction<colored_cloud_t, int64_t*>(
      "COLORED_CLOUD",
      [](const lcm::ReceiveBuffer*, const std::string&, const colored_cloud_t* m, int64_t* n) {
        *n += m->num_points;
      },
      &published_points);
  (void)sub;
  auto* sub2 = lcm.subscribeFunction<colored_cloud_t, int64_t*>(
      "COLORED_CLOUD", [](const lcm::ReceiveBuffer*, const std::string&, const colored_cloud_t*, int64_t* n) { ++*n; },
      &messages);
  (void)sub2;

  odometry_t odo{};
  odo.orientation[0] = 1.0;
  for (int64_t t : {900000, 1000000, 1100000, 1200000}) {
    odo.utime = t;
    lcm.publish("ODOMETRY", &odo);
  }
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
  EXPECT_GT(messages, 0);
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
  colour::ColouredPoints back;
  std::string error;
  ASSERT_TRUE(colour::readPly(node.plyPath(), &back, &error)) << error;
  EXPECT_EQ(back.size(), node.pipeline().map().colouredCount());
  ASSERT_TRUE(colour::readPcd(node.pcdPath(), &back, &error)) << error;
  EXPECT_EQ(back.size(), node.pipeline().map().colouredCount());
}

TEST(ColourNode, RefusesARigWithoutCamera) {
  lcm::LCM lcm("memq://");
  SensorRig rig;
  NodeOptions node_options;
  node_options.name = "colour";
  node_options.quiet = true;
  EXPECT_THROW(colour::ColourNode(lcm, node_options, colour::ColourNodeOptions{}, rig, "."), ConfigError);
}

TEST(ColourConfig, ReadsKeysStrictly) {
  const Config ok = Config::fromString("colour: {voxel_size: 0.1, vignetting: 0.25, map_name: room}");
  const colour::ColourNodeOptions o = colour::readColourOptions(ok.section("colour"));
  EXPECT_DOUBLE_EQ(o.core.voxel_size, 0.1);
  EXPECT_DOUBLE_EQ(o.core.vignetting, 0.25);
  EXPECT_EQ(o.map_name, "room");
  EXPECT_THROW(colour::readColourOptions(Config::fromString("colour: {voxel_sise: 0.1}").section("colour")), ConfigError);
  EXPECT_THROW(colour::readColourOptions(Config::fromString("colour: {voxel_size: -1}").section("colour")), ConfigError);
}
