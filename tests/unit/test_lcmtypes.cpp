// Every LCM type: encode, decode, compare field by field, re-encode to identical bytes; the
// registry identifies each by fingerprint.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "livo/channel_stats_t.hpp"
#include "livo/colored_cloud_t.hpp"
#include "livo/filter_state_t.hpp"
#include "livo/health_t.hpp"
#include "livo/image_t.hpp"
#include "livo/imu_t.hpp"
#include "livo/keyframe_t.hpp"
#include "livo/loop_correction_t.hpp"
#include "livo/message_registry.hpp"
#include "livo/octomap_t.hpp"
#include "livo/odometry_t.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/pose_t.hpp"
#include "livo/progress_t.hpp"
#include "livo/registered_scan_t.hpp"
#include "livo/visual_state_t.hpp"
#include "livo/wheel_odometry_t.hpp"

using namespace livo;

namespace {

template <class T>
std::vector<uint8_t> encode(const T& m) {
  std::vector<uint8_t> buf(m.getEncodedSize());
  EXPECT_EQ(m.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  return buf;
}

// Round trip; returns the decoded copy for field checks.
template <class T>
T roundTrip(const T& m) {
  const auto a = encode(m);
  T d;
  EXPECT_EQ(d.decode(a.data(), 0, static_cast<int>(a.size())), static_cast<int>(a.size()));
  EXPECT_EQ(encode(d), a) << T::getTypeName();
  const MessageType* t = identifyMessage(a.data(), static_cast<int>(a.size()));
  EXPECT_NE(t, nullptr);
  if (t) {
    EXPECT_EQ(t->name, std::string("livo.") + T::getTypeName());
  }
  // a truncated buffer must fail to decode, not crash
  T bad;
  EXPECT_LT(bad.decode(a.data(), 0, static_cast<int>(a.size()) - 1), 0) << T::getTypeName();
  return d;
}

point_cloud_t makeCloud(int n) {
  point_cloud_t c;
  c.utime = 1700000000123456;
  c.frame = "L";
  c.pattern = point_cloud_t::PATTERN_SPINNING;
  c.num_rings = 16;
  c.sweep_duration = 0.1f;
  c.num_points = n;
  for (int i = 0; i < n; ++i) {
    c.x.push_back(0.5f * i);
    c.y.push_back(-0.25f * i);
    c.z.push_back(std::sin(i * 0.1f));
    c.intensity.push_back(static_cast<float>(i % 255));
    c.time_offset.push_back(1e-4f * i);
    c.ring.push_back(static_cast<int16_t>(i % 16));
  }
  return c;
}

}  // namespace

TEST(LcmTypes, Imu) {
  imu_t m;
  m.utime = 42;
  for (int i = 0; i < 3; ++i) m.angular_velocity[i] = 0.1 * (i + 1), m.linear_acceleration[i] = -9.81 + i;
  const imu_t d = roundTrip(m);
  EXPECT_EQ(d.utime, 42);
  EXPECT_DOUBLE_EQ(d.angular_velocity[2], 0.3);
  EXPECT_EQ(d.linear_acceleration[0], -9.81);
}

TEST(LcmTypes, PointCloud) {
  const point_cloud_t d = roundTrip(makeCloud(1000));
  EXPECT_EQ(d.num_points, 1000);
  EXPECT_EQ(d.frame, "L");
  EXPECT_EQ(d.ring[17], 1);
  EXPECT_FLOAT_EQ(d.time_offset[999], 1e-4f * 999);
  EXPECT_FLOAT_EQ(d.x[10], 5.0f);
  roundTrip(makeCloud(0));  // empty scans are valid messages
}

TEST(LcmTypes, Image) {
  image_t m;
  m.utime = 7;
  m.frame = "C";
  m.width = 4;
  m.height = 2;
  m.row_stride = 4;
  m.encoding = image_t::ENCODING_GRAY8;
  m.exposure_time = 0.01f;
  m.data = {1, 2, 3, 4, 5, 6, 7, 8};
  m.size = 8;
  const image_t d = roundTrip(m);
  EXPECT_EQ(d.data[7], 8);
  EXPECT_EQ(d.encoding, int8_t{image_t::ENCODING_GRAY8});
}

// The depth encodings (constants) left the fingerprint as it was: logs recorded before them decode.
TEST(LcmTypes, ImageFingerprintUnchangedByTheDepthEncodings) {
  EXPECT_EQ(static_cast<uint64_t>(image_t::getHash()), 0x804e5142b3028bd3ULL);
  EXPECT_EQ(int{image_t::ENCODING_DEPTH16}, 20);
  EXPECT_EQ(int{image_t::ENCODING_DEPTH32F}, 21);
}

// odometry_t is recorded in every run's outputs.lcmlog: its fields (hence its fingerprint) stay as
// they are, so that livo-report and livo-evaluate read the runs recorded before. The weak
// direction the report names comes from the pose covariance, not from a new field.
TEST(LcmTypes, OdometryFingerprintUnchanged) {
  EXPECT_EQ(static_cast<uint64_t>(odometry_t::getHash()), 0x416e341392b517b3ULL);
}

TEST(LcmTypes, WheelPoseOdometry) {
  wheel_odometry_t w;
  w.utime = 5;
  w.left_speed = 1.25;
  w.right_speed = 1.5;
  EXPECT_EQ(roundTrip(w).right_speed, 1.5);

  pose_t p;
  p.utime = 9;
  p.parent_frame = "W";
  p.child_frame = "I";
  p.position[0] = 1;
  p.orientation[0] = 1;
  EXPECT_EQ(roundTrip(p).child_frame, "I");

  odometry_t o{};
  o.utime = 11;
  o.parent_frame = "W";
  o.child_frame = "I";
  o.orientation[0] = 1;
  for (int i = 0; i < 36; ++i) o.pose_covariance[i] = i;
  o.degenerate = 1;
  o.min_information_eigenvalue = 3.5;
  o.num_residuals = 1234;
  const odometry_t d = roundTrip(o);
  EXPECT_EQ(d.pose_covariance[35], 35);
  EXPECT_EQ(d.degenerate, 1);
  EXPECT_EQ(d.num_residuals, 1234);
}

TEST(LcmTypes, FilterState) {
  filter_state_t s{};
  s.utime = 100;
  s.request_id = 77;
  s.source = "livo-lio";
  s.orientation[0] = 1;
  s.angular_velocity[2] = 0.5;
  s.lidar_orientation[0] = 1;
  s.lidar_position[1] = -0.2;
  s.lidar_time_shift = 0.004;
  s.camera_orientation[3] = 1;
  s.camera_position[0] = 0.1;
  s.camera_time_shift = -0.012;
  for (int i = 0; i < 1024; ++i) s.covariance[i] = i * 1e-3;  // 32x32
  s.valid = 1;
  s.iterations = 3;
  const filter_state_t d = roundTrip(s);
  EXPECT_EQ(d.request_id, 77);
  EXPECT_DOUBLE_EQ(d.covariance[323], 0.323);
  EXPECT_DOUBLE_EQ(d.covariance[1023], 1.023);
  EXPECT_DOUBLE_EQ(d.angular_velocity[2], 0.5);
  EXPECT_DOUBLE_EQ(d.lidar_position[1], -0.2);
  EXPECT_DOUBLE_EQ(d.lidar_time_shift, 0.004);
  EXPECT_DOUBLE_EQ(d.camera_orientation[3], 1.0);
  EXPECT_DOUBLE_EQ(d.camera_position[0], 0.1);
  EXPECT_DOUBLE_EQ(d.camera_time_shift, -0.012);
}

TEST(LcmTypes, RegisteredScanKeyframeLoopCorrection) {
  registered_scan_t r{};
  r.utime = 3;
  r.orientation[0] = 1;
  r.cloud = makeCloud(50);
  r.cloud.frame = "W";
  EXPECT_EQ(roundTrip(r).cloud.num_points, 50);

  keyframe_t k{};
  k.id = 12;
  k.utime = 4;
  k.orientation[0] = 1;
  k.cloud = makeCloud(20);
  k.cloud.frame = "I";
  k.relative_to_id = 11;
  k.relative_covariance[7] = 2.5e-5;
  k.relative_covariance_held_calibration[35] = 4.0e-5;
  const keyframe_t kd = roundTrip(k);
  EXPECT_EQ(kd.id, 12);
  EXPECT_EQ(kd.relative_to_id, 11);
  EXPECT_EQ(kd.relative_covariance[7], 2.5e-5);
  EXPECT_EQ(kd.relative_covariance_held_calibration[35], 4.0e-5);
  EXPECT_EQ(kd.cloud.frame, "I");

  loop_correction_t l{};
  l.utime = 5;
  l.loop_from_id = 30;
  l.loop_to_id = 2;
  l.correction_orientation[0] = 1;
  l.num_keyframes = 3;
  for (int i = 0; i < 3; ++i) {
    l.keyframe_id.push_back(i);
    l.position.push_back({1.0 * i, 2.0, 3.0});
    l.orientation.push_back({1, 0, 0, 0});
  }
  const loop_correction_t ld = roundTrip(l);
  EXPECT_EQ(ld.position[2][0], 2.0);
  EXPECT_EQ(ld.loop_to_id, 2);
}

TEST(LcmTypes, ColouredCloudOctomap) {
  colored_cloud_t c;
  c.utime = 1;
  c.frame = "W";
  c.num_points = 2;
  c.x = {1, 2};
  c.y = {3, 4};
  c.z = {5, 6};
  c.r = {255, 0};
  c.g = {0, 128};
  c.b = {10, 20};
  EXPECT_EQ(roundTrip(c).g[1], 128);

  octomap_t o;
  o.utime = 2;
  o.frame = "W";
  o.tree_type = "OcTree";
  o.resolution = 0.1;
  o.binary = 1;
  o.data = std::vector<uint8_t>(300, 0xAB);
  o.size = 300;
  EXPECT_EQ(roundTrip(o).data[299], 0xAB);
}

TEST(LcmTypes, ProgressHealth) {
  progress_t p{};
  p.utime = 9;
  p.node = "lio";
  p.sequence = 3;
  p.finished = 0;
  p.num_inputs = 2;
  p.input_channel = {"IMU", "LIDAR"};
  p.handled = {200, 10};
  p.num_outputs = 1;
  p.output_channel = {"ODOMETRY"};
  p.published = {10};
  p.published_bytes = {1000};
  p.num_quiet = 1;
  p.quiet_channel = {"IMU"};
  p.quiet_from = {100};
  p.quiet_before = {200};
  const progress_t pd = roundTrip(p);
  EXPECT_EQ(pd.input_channel[1], "LIDAR");
  ASSERT_EQ(pd.num_quiet, 1);
  EXPECT_EQ(pd.quiet_channel[0], "IMU");
  EXPECT_EQ(pd.quiet_before[0], 200);
  EXPECT_EQ(pd.handled[0], 200);
  EXPECT_EQ(pd.published_bytes[0], 1000);

  health_t h;
  h.utime = 1;
  h.node = "lio";
  h.level = health_t::LEVEL_WARN;
  h.message = "IMU gap";
  h.peak_rss_mb = 12.5;
  channel_stats_t c;
  c.channel = "LIDAR";
  c.messages = 10;
  c.decode_failures = 1;
  c.rejected = 2;
  c.median_ms = 3;
  c.p90_ms = 4;
  c.max_ms = 5;
  EXPECT_EQ(roundTrip(c).rejected, 2);
  h.channels = {c};
  h.num_channels = 1;
  EXPECT_EQ(roundTrip(h).channels[0].channel, "LIDAR");
}

TEST(LcmTypes, RegistryHasEveryTypeOnce) {
  const auto& types = messageTypes();
  EXPECT_EQ(types.size(), 16u);
  for (size_t i = 0; i < types.size(); ++i)
    for (size_t j = i + 1; j < types.size(); ++j) EXPECT_NE(types[i].fingerprint, types[j].fingerprint);
  const uint8_t junk[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_EQ(identifyMessage(junk, 8), nullptr);
  EXPECT_EQ(identifyMessage(junk, 4), nullptr);
}

TEST(LcmTypes, LeadingUtimeReadAndWrittenInPlace) {
  imu_t m{};
  m.utime = 1700000000123456;
  auto buf = encode(m);
  int64_t t = 0;
  ASSERT_TRUE(messageUtime(buf.data(), static_cast<int>(buf.size()), &t));
  EXPECT_EQ(t, 1700000000123456);
  ASSERT_TRUE(setMessageUtime(buf.data(), static_cast<int>(buf.size()), -42));
  imu_t d;
  ASSERT_EQ(d.decode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  EXPECT_EQ(d.utime, -42);
  // every stamped type leads with its utime (a recorder stamps its log events with it: a KEYFRAME
  // stamped with whatever came last on the bus made two replays' logs differ); channel_stats_t has none
  keyframe_t k{};
  k.utime = 5;
  k.id = 9;
  const auto kb = encode(k);
  ASSERT_TRUE(messageUtime(kb.data(), static_cast<int>(kb.size()), &t));
  EXPECT_EQ(t, 5);
  int with_utime = 0;
  for (const auto& type : messageTypes()) with_utime += type.leading_utime;
  EXPECT_EQ(with_utime, 15);  // all but channel_stats_t
}

// countNonFinite sees a NaN or an infinity in any floating-point field, nested ones included.
TEST(LcmTypes, CountNonFiniteFindsEveryBadValue) {
  auto count = [](const auto& m) {
    const auto b = encode(m);
    return countNonFinite(b.data(), static_cast<int>(b.size()));
  };
  odometry_t odo{};
  odo.orientation[0] = 1.0;
  EXPECT_EQ(count(odo), 0);
  odo.position[1] = NAN;
  odo.pose_covariance[35] = INFINITY;
  EXPECT_EQ(count(odo), 2);

  registered_scan_t scan{};
  scan.orientation[0] = 1.0;
  scan.cloud.num_points = 3;
  scan.cloud.x = {0.f, 1.f, NAN};
  scan.cloud.y = {0.f, 1.f, 2.f};
  scan.cloud.z = {0.f, -INFINITY, 2.f};
  scan.cloud.intensity.assign(3, 0.f);
  scan.cloud.time_offset.assign(3, 0.f);
  scan.cloud.ring.assign(3, 0);
  EXPECT_EQ(count(scan), 2);

  loop_correction_t c{};
  c.correction_orientation[0] = 1.0;
  c.num_keyframes = 2;
  c.keyframe_id = {0, 1};
  c.position = {{0.0, 0.0, 0.0}, {0.0, NAN, 0.0}};
  c.orientation = {{1.0, 0.0, 0.0, 0.0}, {1.0, 0.0, 0.0, 0.0}};
  EXPECT_EQ(count(c), 1);

  health_t h{};
  h.num_channels = 1;
  h.channels.resize(1);
  h.channels[0].median_ms = NAN;
  EXPECT_EQ(count(h), 1);

  visual_state_t v{};
  v.orientation[0] = 1.0;
  EXPECT_EQ(count(v), 0);
  v.velocity[2] = NAN;
  v.pose_covariance[7] = -INFINITY;
  EXPECT_EQ(count(v), 2);

  const uint8_t junk[12] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  EXPECT_EQ(countNonFinite(junk, 12), -1);  // not a project message
  const auto truncated = encode(odo);
  EXPECT_EQ(countNonFinite(truncated.data(), static_cast<int>(truncated.size()) - 4), -1);
}
