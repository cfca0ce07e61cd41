#include "livo/ros_bridge/ros_bridge_config.hpp"

#include <ostream>
#include <stdexcept>

#include "livo/import/import_job.hpp"
#include "livo/sensor_rig.hpp"

namespace livo::ros_bridge {

namespace {

void readTopics(const Config& c, import::RosbagImportOptions& in) {
  const Config t = c.optionalSection("topics");
  t.readOptional("imu", in.imu_topic);
  t.readOptional("lidar", in.lidar_topic);
  t.readOptional("camera", in.camera_topic);
  t.readOptional("camera_right", in.camera_right_topic);
  t.readOptional("depth", in.depth_topic);
  t.readOptional("ground_truth", in.ground_truth_topic);
  t.readOptional("ground_truth_frame", in.ground_truth_tf_frame);
}

void flagTopics(const RosBridgeFlags& f, import::RosbagImportOptions& in) {
  auto over = [](std::string& topic, const std::string& flag) {
    if (!flag.empty()) topic = flag;
  };
  over(in.imu_topic, f.imu);
  over(in.lidar_topic, f.lidar);
  over(in.camera_topic, f.camera);
  over(in.camera_right_topic, f.camera_right);
  over(in.depth_topic, f.depth);
  over(in.ground_truth_topic, f.ground_truth);
  over(in.ground_truth_tf_frame, f.ground_truth_frame);
}

/// livo-import's preset: fills the empty topics and sets the LiDAR's stamp convention and sweep.
void applyImportPreset(const std::string& preset, import::RosbagImportOptions& in) {
  import::ImportJob job;
  job.format = "rosbag";
  job.preset = preset;
  job.rosbag = in;
  import::applyPreset(job);
  in = job.rosbag;
}

import::LidarStampConvention stampConvention(const std::string& s, const std::string& where){
    if (s == "start") return import::LidarStampConvention::kStart;
if (s == "end") return import::LidarStampConvention::kEnd;
throw ConfigError(where + ": expected start or end, got '" + s + "'");
}  // namespace

void readLidar(const Config& c, import::PointCloudConversionOptions& lidar) {
  const Config l = c.optionalSection("lidar");
  std::string stamp;
  if (l.readOptional("stamp", stamp)) lidar.stamp = stampConvention(stamp, l.where("stamp"));
  l.readOptional("sweep_duration", lidar.sweep_duration);
  l.readOptional("rings", lidar.num_rings);
  l.readOptional("time_field", lidar.time_field);
  l.readOptional("time_unit", lidar.time_unit);
  l.readOptional("azimuth_times", lidar.azimuth_times);
}

void flagLidar(const RosBridgeFlags& f, import::PointCloudConversionOptions& lidar) {
  if (!f.lidar_stamp.empty()) lidar.stamp = stampConvention(f.lidar_stamp, "--lidar-stamp");
  if (f.sweep_duration) lidar.sweep_duration = *f.sweep_duration;
  if (f.lidar_rings) lidar.num_rings = *f.lidar_rings;
}

void readImuUnits(const Config& c, import::ImuUnitOptions& units) {
  const Config u = c.optionalSection("imu_units");
  u.readOptional("accel", units.accel);
  u.readOptional("gyro", units.gyro);
}

void readOutputs(const Config& c, RosBridgeNodeOptions& n) {
  const Config f = c.optionalSection("frames");
  f.readOptional("world", n.frames.world);
  f.readOptional("body", n.frames.body);
  const Config o = c.optionalSection("outputs");
  o.readOptional("odometry", n.outputs.odometry);
  o.readOptional("registered_scan", n.outputs.registered_scan);
  o.readOptional("colored_cloud", n.outputs.colored_cloud);
  o.readOptional("tf", n.outputs.tf);
}

void readChannels(const Config& c, RosBridgeNodeOptions& n) {
  const Config ch = c.optionalSection("channels");
  import::ChannelNames& s = n.input.channels;
  ch.readOptional("imu", s.imu);
  ch.readOptional("lidar", s.lidar);
  ch.readOptional("camera", s.camera);
  ch.readOptional("camera_right", s.camera_right);
  ch.readOptional("depth", s.depth);
  ch.readOptional("ground_truth", s.ground_truth);
  ch.readOptional("odometry", n.odometry_channel);
  ch.readOptional("registered_scan", n.registered_scan_channel);
  ch.readOptional("colored_cloud", n.colored_cloud_channel);
}

void checkRanges(const Config& c, const RosBridgeNodeOptions& n) {
  auto fail = [&](const std::string& key, const std::string& what) { throw ConfigError(c.where(key) + ": " + what); };
  const import::PointCloudConversionOptions& l = n.input.lidar;
  if (!(l.sweep_duration > 0.0 && l.sweep_duration <= 1.0)) fail("lidar.sweep_duration", "must be in (0, 1] s");
  if (l.num_rings < 0 || l.num_rings > 1024) fail("lidar.rings", "must be in [0, 1024] (0: from the cloud)");
  for (const std::string* frame : {&n.frames.world, &n.frames.body})
    if (frame->empty()) fail(frame == &n.frames.world ? "frames.world" : "frames.body", "must not be empty");
  if (n.frames.world == n.frames.body) fail("frames.body", "must differ from frames.world");
  if (n.imu_queue < 1) fail("imu_queue", "must be >= 1");
  if (n.sensor_queue < 1) fail("sensor_queue", "must be >= 1");
  const import::RosbagImportOptions& in = n.input;
  if (in.imu_topic.empty() && in.lidar_topic.empty() && in.camera_topic.empty() && in.camera_right_topic.empty() &&
      in.depth_topic.empty() && in.ground_truth_topic.empty())
    fail("topics", "no ROS topic to bridge: give topics (--imu, --lidar, --camera, ...) or a --preset");
}

}  // namespace livo::ros_bridge

RosBridgeNodeOptions readRosBridgeNodeOptions(const Config& root, const RosBridgeFlags& flags) {
  const Config c = root.optionalSection("ros_bridge");
  RosBridgeNodeOptions n;
  n.input.auto_map = false;  // a live bus has no bag to choose from: topics are named
  n.input.progress = false;
  if (root.has("rig")) n.input.channels = import::channelNamesOf(readSensorRig(root.section("rig")), n.input.channels);
  c.readOptional("preset", n.preset);
  if (!flags.preset.empty()) n.preset = flags.preset;
  readTopics(c, n.input);
  flagTopics(flags, n.input);
  applyImportPreset(n.preset, n.input);
  readLidar(c, n.input.lidar);
  flagLidar(flags, n.input.lidar);
  readImuUnits(c, n.input.imu_units);
  readOutputs(c, n);
  if (!flags.world_frame.empty()) n.frames.world = flags.world_frame;
  if (!flags.body_frame.empty()) n.frames.body = flags.body_frame;
  readChannels(c, n);
  c.readOptional("imu_queue", n.imu_queue);
  c.readOptional("sensor_queue", n.sensor_queue);
  if (!c.isNull()) c.checkAllUsed();
  checkRanges(c, n);
  return n;
}

void printOptions(const RosBridgeNodeOptions& o, std::ostream& os) {
  const import::RosbagImportOptions& in = o.input;
  auto topic = [&](const char* role, const std::string& t, const std::string& channel) {
    if (!t.empty()) os << "  " << role << ": " << t << " -> " << channel << "\n";
  };
  os << "ros_bridge: ROS topics in" << (o.preset.empty() ? "" : " (preset " + o.preset + ")") << "\n";
  topic("imu", in.imu_topic, in.channels.imu);
  topic("lidar", in.lidar_topic, in.channels.lidar);
  topic("camera", in.camera_topic, in.channels.camera);
  topic("camera_right", in.camera_right_topic, in.channels.camera_right);
  topic("depth", in.depth_topic, in.channels.depth);
  topic("ground_truth", in.ground_truth_topic, in.channels.ground_truth);
  if (!in.lidar_topic.empty())
    os << "  lidar stamps the sweep " << (in.lidar.stamp == import::LidarStampConvention::kEnd ? "end" : "start")
       << ", sweep " << in.lidar.sweep_duration << " s, rings "
       << (in.lidar.num_rings ? std::to_string(in.lidar.num_rings) : std::string("from the cloud")) << "\n";
  os << "ros_bridge: outputs to ROS in frame " << o.frames.world << " (body " << o.frames.body << ")\n";
  auto out = [&](const std::string& channel, const std::string& t, const char* type) {
    os << "  " << channel << " -> " << (t.empty() ? std::string("(not published)") : t + " (" + type + ")") << "\n";
  };
  out(o.odometry_channel, o.outputs.odometry, "nav_msgs/Odometry");
  if (o.outputs.tf) os << "  " << o.odometry_channel << " -> /tf " << o.frames.world << " -> " << o.frames.body << "\n";
  out(o.registered_scan_channel, o.outputs.registered_scan, "sensor_msgs/PointCloud2");
  out(o.colored_cloud_channel, o.outputs.colored_cloud, "sensor_msgs/PointCloud2, rgb");
}

}  // namespace livo::ros_bridge
