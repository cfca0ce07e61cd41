// livo-ros-bridge without a network: ROS 1 messages serialised by roscpp's own serialisation go
// through livo-import's RosMessageConverter as the bridge runs it, and the outputs' ROS messages are read back
// with livo-import's decoders (a reader this code did not write); the config and its precedence.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <ros/serialization.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>

#include "livo/import/byte_reader.hpp"
#include "livo/import/point_cloud2_conversion.hpp"
#include "livo/import/ros_message_converter.hpp"
#include "livo/import/ros_messages.hpp"
#include "livo/ros_bridge/ros_bridge_config.hpp"
#include "livo/ros_bridge/ros_output_messages.hpp"

namespace {

using namespace livo;
using namespace livo::ros_bridge;

/// What the converter emits.
struct Collected : import::MessageObserver {
  std::vector<std::pair<std::string, imu_t>> imu;
  std::vector<std::pair<std::string, point_cloud_t>> clouds;
  std::vector<std::pair<std::string, image_t>> images;
  std::vector<std::pair<std::string, pose_t>> poses;
  void observe(const std::string& c, const imu_t& m) override { imu.emplace_back(c, m); }
  void observe(const std::string& c, const point_cloud_t& m) override { clouds.emplace_back(c, m); }
  void observe(const std::string& c, const image_t& m) override { images.emplace_back(c, m); }
  void observe(const std::string& c, const pose_t& m) override { poses.emplace_back(c, m); }
  size_t total() const { return imu.size() + clouds.size() + images.size() + poses.size(); }
};

template <class M>
std::vector<uint8_t> serialise(const M& m) {
  std::vector<uint8_t> bytes(ros::serialization::serializationLength(m));
  ros::serialization::OStream stream(bytes.data(), static_cast<uint32_t>(bytes.size()));
  ros::serialization::serialize(stream, m);
  return bytes;
}

/// A serialised message as the bridge's subscription hands it to the converter.
struct Wire {
  std::string topic, type, md5;
  std::vector<uint8_t> bytes;
  import::RosWireMessage message() const {import::RosWireMessage m;
  m.topic = &topic;
  m.type = &type;
  m.md5sum = &md5;
  m.format = import::RosWireFormat::kRos1;
  m.receive_time_ns = 1700000123456789000LL;  // the arrival time
  m.data = bytes.data();
  m.size = bytes.size();
  m.where = "topic " + topic;
  return m;
}
};  // namespace

template <class M>
Wire wire(const std::string& topic, const M& msg) {
  return {topic, ros::message_traits::datatype<M>(), ros::message_traits::md5sum<M>(), serialise(msg)};
}

sensor_msgs::Imu imuMessage(uint32_t sec, uint32_t nsec) {
  sensor_msgs::Imu m;
  m.header.stamp = ros::Time(sec, nsec);
  m.angular_velocity.x = 0.01;
  m.angular_velocity.y = -0.02;
  m.angular_velocity.z = 0.03;
  m.linear_acceleration.x = 0.1;
  m.linear_acceleration.y = 0.2;
  m.linear_acceleration.z = 9.79;
  return m;
}

/// A velodyne_pointcloud-style cloud: x y z intensity ring time (relative seconds), 22 bytes a point.
sensor_msgs::PointCloud2 velodyneCloud(uint32_t sec, uint32_t nsec, int points) {
  using sensor_msgs::PointField;
  sensor_msgs::PointCloud2 m;
  m.header.stamp = ros::Time(sec, nsec);
  m.height = 1;
  m.width = static_cast<uint32_t>(points);
  auto f = [](const char* n, uint32_t o, uint8_t t) {
    PointField p;
    p.name = n;
    p.offset = o;
    p.datatype = t;
    p.count = 1;
    return p;
  };
  m.fields = {f("x", 0, PointField::FLOAT32),    f("y", 4, PointField::FLOAT32),
              f("z", 8, PointField::FLOAT32),    f("intensity", 12, PointField::FLOAT32),
              f("ring", 16, PointField::UINT16), f("time", 18, PointField::FLOAT32)};
  m.point_step = 22;
  m.row_step = 22 * m.width;
  m.data.resize(m.row_step);
  for (int i = 0; i < points; ++i) {
    const float v[4] = {1.0f + i, -2.0f + 0.5f * i, 0.25f * i, 10.0f * i};
    const uint16_t ring = static_cast<uint16_t>(i % 16);
    const float t = 0.001f * i;
    uint8_t* p = &m.data[static_cast<size_t>(i) * 22];
    std::memcpy(p, v, 16);
    std::memcpy(p + 16, &ring, 2);
    std::memcpy(p + 18, &t, 4);
  }
  return m;
}

/// The inputs as readRosBridgeNodeOptions leaves them (topics named, none chosen automatically),
/// with the IMU's units given (decided at once: nothing held back).
import::RosbagImportOptions bridgeInput(){import::RosbagImportOptions o;
o.auto_map = false;
o.progress = false;
o.imu_units.accel = "m/s2";
o.imu_topic = "/imu";
o.lidar_topic = "/velodyne_points";
o.camera_topic = "/cam/left";
o.camera_right_topic = "/cam/right";
o.depth_topic = "/cam/depth";
o.ground_truth_topic = "/gt";
return o;
}

/// livo-import's converter as the bridge constructs it.
import::RosMessageConverter bridgeConverter(const import::RosbagImportOptions& o, Collected& out,
                                            import::ImportReport& report){report.setQuiet(true);
return import::RosMessageConverter(o, out, report, "the arrival time");
}

TEST(RosInput, ImuSampleAsLivoImportWritesIt) {
  Collected out;
  import::ImportReport report;
  const import::RosbagImportOptions options = bridgeInput();
  import::RosMessageConverter converter = bridgeConverter(options, out, report);
  ASSERT_TRUE(converter.handle(wire("/imu", imuMessage(1700000000, 5000)).message()));
  ASSERT_EQ(out.imu.size(), 1u);
  EXPECT_EQ(out.imu[0].first, "IMU");
  const imu_t& s = out.imu[0].second;
  EXPECT_EQ(s.utime, 1700000000000005LL);
  EXPECT_DOUBLE_EQ(s.angular_velocity[1], -0.02);
  EXPECT_DOUBLE_EQ(s.linear_acceleration[2], 9.79);
}

TEST(RosInput, ImuUnitsDecidedAsTheImporterDecides) {
  Collected out;
  import::ImportReport report;
  import::RosbagImportOptions options = bridgeInput();
  options.imu_units.accel = "auto";  // the first samples are held until decided
  import::RosMessageConverter converter = bridgeConverter(options, out, report);
  for (uint32_t i = 0; i < 3; ++i) {
    sensor_msgs::Imu m = imuMessage(1700000000, i * 5000000);
    m.linear_acceleration.z = 1.0;  // in g, as a Livox IMU reports it
    EXPECT_TRUE(converter.handle(wire("/imu", m).message()));
  }
  EXPECT_EQ(out.imu.size(), 0u);
  converter.finish();
  ASSERT_EQ(out.imu.size(), 3u);
  EXPECT_NEAR(out.imu[2].second.linear_acceleration[2], import::kStandardGravity, 1e-12);
  EXPECT_FALSE(report.notes().empty());
}

TEST(RosInput, CloudWithPerPointTimesAndTheEndStampConvention) {
  Collected out;
  import::ImportReport report;
  const Wire cloud = wire("/velodyne_points", velodyneCloud(1700000001, 0, 50));
  const import::RosbagImportOptions start_options = bridgeInput();
  import::RosMessageConverter start = bridgeConverter(start_options, out, report);
  ASSERT_TRUE(start.handle(cloud.message()));
  import::RosbagImportOptions end_options = bridgeInput();
  end_options.lidar.stamp = import::LidarStampConvention::kEnd;  // as --lidar-stamp end / the ntu_viral preset
  import::RosMessageConverter end = bridgeConverter(end_options, out, report);
  ASSERT_TRUE(end.handle(cloud.message()));
  ASSERT_EQ(out.clouds.size(), 2u);
  const point_cloud_t& c = out.clouds[0].second;
  EXPECT_EQ(out.clouds[0].first, "LIDAR");
  EXPECT_EQ(c.utime, 1700000001000000LL);
  ASSERT_EQ(c.num_points, 50);
  EXPECT_FLOAT_EQ(c.x[3], 4.0f);
  EXPECT_FLOAT_EQ(c.intensity[3], 30.0f);
  EXPECT_EQ(c.ring[3], 3);
  EXPECT_NEAR(c.time_offset[3], 0.003f, 1e-6);
  EXPECT_EQ(out.clouds[1].second.utime, 1700000001000000LL - 100000);  // stamp - sweep_duration
}

sensor_msgs::Image image(const std::string& encoding, uint32_t bytes_per_pixel) {
  sensor_msgs::Image m;
  m.header.stamp = ros::Time(1700000002, 500000000);
  m.width = 4;
  m.height = 3;
  m.encoding = encoding;
  m.step = m.width * bytes_per_pixel;
  m.data.assign(static_cast<size_t>(m.step) * m.height, 7);
  return m;
}

TEST(RosInput, ImagesByRoleAsTheImporterWritesThem) {
  Collected out;
  import::ImportReport report;
  const import::RosbagImportOptions options = bridgeInput();
  import::RosMessageConverter converter = bridgeConverter(options, out, report);
  const sensor_msgs::Image grey = image("mono8", 1), depth = image("16UC1", 2);
  ASSERT_TRUE(converter.handle(wire("/cam/left", grey).message()));
  ASSERT_TRUE(converter.handle(wire("/cam/right", grey).message()));
  ASSERT_TRUE(converter.handle(wire("/cam/depth", depth).message()));
  ASSERT_EQ(out.images.size(), 3u);
  EXPECT_EQ(out.images[0].first, "CAMERA");
  EXPECT_EQ(out.images[0].second.frame, "C");
  EXPECT_EQ(out.images[0].second.encoding, int8_t{image_t::ENCODING_GRAY8});
  EXPECT_EQ(out.images[0].second.utime, 1700000002500000LL);
  EXPECT_EQ(out.images[1].first, "CAMERA_RIGHT");
  EXPECT_EQ(out.images[1].second.frame, "C1");
  EXPECT_EQ(out.images[2].first, "DEPTH");
  EXPECT_EQ(out.images[2].second.encoding, int8_t{image_t::ENCODING_DEPTH16});
  EXPECT_EQ(out.images[2].second.width, 4);
  // a colour camera's encoding the importer does not know is refused, as in a bag
  EXPECT_FALSE(converter.handle(wire("/cam/left", image("yuv422", 2)).message()));
  EXPECT_EQ(out.images.size(), 3u);
}

TEST(RosInput, GroundTruthPoseAndZeroStamps) {
  Collected out;
  import::ImportReport report;
  const import::RosbagImportOptions options = bridgeInput();
  import::RosMessageConverter converter = bridgeConverter(options, out, report);
  geometry_msgs::PoseStamped p;
  p.header.stamp = ros::Time(0, 0);  // no stamp: the arrival time is used, as the importer uses the bag's
  p.pose.position.x = 1.5;
  p.pose.orientation.x = 0.5;
  p.pose.orientation.y = 0.5;
  p.pose.orientation.z = 0.5;
  p.pose.orientation.w = 0.5;
  ASSERT_TRUE(converter.handle(wire("/gt", p).message()));
  ASSERT_EQ(out.poses.size(), 1u);
  const pose_t& q = out.poses[0].second;
  EXPECT_EQ(q.utime, 1700000123456789LL);
  EXPECT_EQ(q.parent_frame, "W");
  EXPECT_DOUBLE_EQ(q.position[0], 1.5);
  EXPECT_DOUBLE_EQ(q.orientation[0], 0.5);  // w first
  EXPECT_EQ(report.skipped().count("header.stamp is zero: stamped with the arrival time instead"), 1u);
}

TEST(RosInput, GroundTruthFromTfOneChildFrame) {
  Collected out;
  import::ImportReport report;
  import::RosbagImportOptions options = bridgeInput();
  options.ground_truth_topic = "/tf";
  options.ground_truth_tf_frame = "vicon/body";  // --ground-truth-frame
  import::RosMessageConverter converter = bridgeConverter(options, out, report);
  tf2_msgs::TFMessage tf;
  tf.transforms.resize(2);
  tf.transforms[0].header.stamp = ros::Time(1700000004, 0);
  tf.transforms[0].child_frame_id = "base_link";
  tf.transforms[1].header.stamp = ros::Time(1700000004, 10000);
  tf.transforms[1].child_frame_id = "vicon/body";
  tf.transforms[1].transform.translation.y = 2.5;
  tf.transforms[1].transform.rotation.w = 1.0;
  ASSERT_TRUE(converter.handle(wire("/tf", tf).message()));
  ASSERT_EQ(out.poses.size(), 1u);
  EXPECT_EQ(out.poses[0].second.utime, 1700000004000010LL);
  EXPECT_DOUBLE_EQ(out.poses[0].second.position[1], 2.5);
  EXPECT_EQ(report.skippedTotal(), 1);  // the transform to base_link
}

TEST(RosInput, RefusesWhatTheImporterRefuses) {
  Collected out;
  import::ImportReport report;
  const import::RosbagImportOptions options = bridgeInput();
  import::RosMessageConverter converter = bridgeConverter(options, out, report);
  const sensor_msgs::Imu imu = imuMessage(1700000000, 0);
  Wire other_md5 = wire("/imu", imu);
  other_md5.md5 = "0123456789abcdef0123456789abcdef";
  EXPECT_FALSE(converter.handle(other_md5.message()));
  EXPECT_FALSE(converter.handle(wire("/velodyne_points", imu).message()));  // an Imu cannot be the LiDAR
  Wire cut = wire("/imu", imu);
  cut.bytes.resize(cut.bytes.size() - 10);
  EXPECT_FALSE(converter.handle(cut.message()));
  Wire unknown = wire("/imu", imu);
  unknown.type = "std_msgs/String";
  EXPECT_FALSE(converter.handle(unknown.message()));
  EXPECT_EQ(out.total(), 0u);
  EXPECT_EQ(report.skippedTotal(), 4);
  bool named_field = false;
  for (const auto& [reason, s] : report.skipped())
    named_field |= reason.find("undecodable sensor_msgs/Imu on /imu") != std::string::npos;
  EXPECT_TRUE(named_field);
}

/// Reads a serialised ROS message back with livo-import's decoders.
template <class M>
import::ByteReader readerOf(const std::vector<uint8_t>& bytes) {
  return import::ByteReader(bytes.data(), bytes.size(), "test");
}

TEST(RosOutput, OdometryReadBackByTheImporter) {
  odometry_t o{};
  o.utime = 1700000001250000LL;
  o.position[0] = 1.0;
  o.position[1] = 2.0;
  o.position[2] = 3.0;
  const double s = std::sqrt(0.5);  // 90 deg about z
  o.orientation[0] = s;
  o.orientation[3] = s;
  o.velocity[0] = 1.0;  // world x = body -y
  o.angular_velocity[2] = 0.5;
  const double rot_var[3] = {1e-4, 2e-4, 3e-4}, pos_var[3] = {4e-2, 5e-2, 6e-2};
  for (int i = 0; i < 3; ++i) {
    o.pose_covariance[i * 6 + i] = rot_var[i];
    o.pose_covariance[(i + 3) * 6 + i + 3] = pos_var[i];
  }
  o.velocity_covariance[0] = 0.01;
  const RosFrames frames{"odom", "base_link"};
  const nav_msgs::Odometry m = odometryToRos(o, frames);
  const auto bytes = serialise(m);
  import::ByteReader r = readerOf<nav_msgs::Odometry>(bytes);
  const import::RosStampedPose p = import::decodeRosOdometry(r);
  EXPECT_EQ(p.header.stampNs(), 1700000001250000000LL);
  EXPECT_EQ(p.header.frame_id, "odom");
  EXPECT_EQ(p.child_frame_id, "base_link");
  EXPECT_DOUBLE_EQ(p.position[1], 2.0);
  EXPECT_NEAR(p.orientation_xyzw[2], s, 1e-15);
  EXPECT_NEAR(p.orientation_xyzw[3], s, 1e-15);
  // ROS: [x y z | rotation about the world axes]; a body x rotation is a world y rotation here
  EXPECT_NEAR(m.pose.covariance[0], 4e-2, 1e-15);
  EXPECT_NEAR(m.pose.covariance[2 * 6 + 2], 6e-2, 1e-15);
  EXPECT_NEAR(m.pose.covariance[3 * 6 + 3], 2e-4, 1e-15);
  EXPECT_NEAR(m.pose.covariance[4 * 6 + 4], 1e-4, 1e-15);
  EXPECT_NEAR(m.pose.covariance[5 * 6 + 5], 3e-4, 1e-15);
  EXPECT_NEAR(m.twist.twist.linear.y, -1.0, 1e-12);  // the velocity in the body frame
  EXPECT_NEAR(m.twist.covariance[1 * 6 + 1], 0.01, 1e-15);
  EXPECT_DOUBLE_EQ(m.twist.twist.angular.z, 0.5);
  const geometry_msgs::TransformStamped t = odometryTransform(o, frames);
  EXPECT_EQ(t.header.frame_id, "odom");
  EXPECT_EQ(t.child_frame_id, "base_link");
  EXPECT_DOUBLE_EQ(t.transform.translation.z, 3.0);
  o.utime = -1;
  EXPECT_THROW(odometryToRos(o, frames), std::invalid_argument);
}

TEST(RosOutput, RegisteredScanReadBackByTheImporter) {
  registered_scan_t scan{};
  scan.utime = 1700000002100000LL;
  point_cloud_t& c = scan.cloud;
  c.utime = 1700000002000000LL;
  c.frame = "W";
  c.num_points = 5;
  for (int i = 0; i < 5; ++i) {
    c.x.push_back(1.0f + i);
    c.y.push_back(2.0f);
    c.z.push_back(-0.5f * i);
    c.intensity.push_back(7.0f * i);
    c.time_offset.push_back(0.02f * i);
    c.ring.push_back(static_cast<int16_t>(i));
  }
  const sensor_msgs::PointCloud2 m = registeredScanToRos(scan, RosFrames{"odom", "base_link"});
  EXPECT_EQ(m.header.frame_id, "odom");
  const auto bytes = serialise(m);
  import::ByteReader r = readerOf<sensor_msgs::PointCloud2>(bytes);
  const import::RosPointCloud2 back = import::decodeRosPointCloud2(r);
  EXPECT_EQ(back.header.stampNs(), 1700000002100000000LL);
  import::PointCloudConversionOptions options;
  options.frame = "W";
  const import::PointCloudConversion read = import::convertPointCloud2(back, options, "test");
  ASSERT_EQ(read.cloud.num_points, 5);
  for (int i = 0; i < 5; ++i) {
    EXPECT_FLOAT_EQ(read.cloud.x[i], c.x[i]);
    EXPECT_FLOAT_EQ(read.cloud.z[i], c.z[i]);
    EXPECT_FLOAT_EQ(read.cloud.intensity[i], c.intensity[i]);
    EXPECT_EQ(read.cloud.ring[i], c.ring[i]);
    EXPECT_NEAR(read.cloud.time_offset[i], c.time_offset[i], 1e-6);
  }
}

TEST(RosOutput, ColouredCloudPacksRgbAsRvizReadsIt) {
  colored_cloud_t cloud{};
  cloud.utime = 1700000003000000LL;
  cloud.num_points = 2;
  cloud.x = {1.0f, 2.0f};
  cloud.y = {3.0f, 4.0f};
  cloud.z = {5.0f, 6.0f};
  cloud.r = {255, 1};
  cloud.g = {128, 2};
  cloud.b = {0, 3};
  const sensor_msgs::PointCloud2 m = colouredCloudToRos(cloud, RosFrames{});
  ASSERT_EQ(m.fields.size(), 4u);
  EXPECT_EQ(m.fields[3].name, "rgb");
  EXPECT_EQ(m.header.frame_id, "world");
  uint32_t rgb[2];
  std::memcpy(&rgb[0], &m.data[12], 4);
  std::memcpy(&rgb[1], &m.data[16 + 12], 4);
  EXPECT_EQ(rgb[0], 0x00FF8000u);
  EXPECT_EQ(rgb[1], 0x00010203u);
  float y1;
  std::memcpy(&y1, &m.data[16 + 4], 4);
  EXPECT_FLOAT_EQ(y1, 4.0f);
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(RosBridgeConfig, PresetFlagsAndConfigInLivoImportsOrder) {
  const Config cfg = Config::fromString(
      "rig: {channels: {imu: IMU0, lidar: LIDAR0}, imu: {rate_hz: 200, gyro_noise_density: 1.0e-4, "
      "gyro_random_walk: 1.0e-5, accel_noise_density: 1.0e-3, accel_random_walk: 1.0e-4}}\n"
      "ros_bridge: {preset: ntu_viral, topics: {camera: /cam}, lidar: {sweep_duration: 0.05}}\n",
      "b.yaml");
  RosBridgeFlags flags;
  flags.imu = "/my_imu";
  flags.world_frame = "map";
  const RosBridgeNodeOptions o = readRosBridgeNodeOptions(cfg, flags);
  EXPECT_EQ(o.input.imu_topic, "/my_imu");                    // the flag
  EXPECT_EQ(o.input.camera_topic, "/cam");                    // the config
  EXPECT_EQ(o.input.lidar_topic, "/os1_cloud_node1/points");  // the preset fills what is empty
  EXPECT_EQ(o.input.lidar.stamp, import::LidarStampConvention::kEnd);
  EXPECT_DOUBLE_EQ(o.input.lidar.sweep_duration, 0.05);  // the config over the preset
  EXPECT_EQ(o.input.channels.imu, "IMU0");               // the rig's channels
  EXPECT_EQ(o.frames.world, "map");
  EXPECT_EQ(o.frames.body, "body");
  // the roles the bridge subscribes to, as its converter maps them
  Collected out;
  import::ImportReport report;
  const import::RosMessageConverter converter = bridgeConverter(o.input, out, report);
  const auto roles = converter.roleTopics();
  EXPECT_NE(std::find(roles.begin(), roles.end(), std::make_pair(std::string("camera"), std::string("/cam"))),
            roles.end());
}

TEST(RosBridgeConfig, ErrorsNameTheKey) {
  auto error = [](const std::string& yaml) {
    return errorOf([&] { readRosBridgeNodeOptions(Config::fromString(yaml, "b.yaml")); });
  };
  EXPECT_NE(error("ros_bridge: {topics: {imu: /i, lidr: /l}}").find("ros_bridge.topics.lidr"), std::string::npos);
  EXPECT_NE(error("ros_bridge: {frames: {world: w}}").find("no ROS topic"), std::string::npos);
  EXPECT_NE(error("ros_bridge: {topics: {imu: /i}, frames: {world: a, body: a}}").find("frames.body"),
            std::string::npos);
  EXPECT_NE(error("ros_bridge: {topics: {imu: /i}, lidar: {stamp: middle}}").find("ros_bridge.lidar.stamp"),
            std::string::npos);
  EXPECT_NE(error("ros_bridge: {preset: nope, topics: {imu: /i}}").find("unknown preset 'nope'"), std::string::npos);
}

}  // namespace
