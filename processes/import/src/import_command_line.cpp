#include "livo/import/import_command_line.hpp"

#include <ostream>
#include <stdexcept>

#include "livo/config.hpp"
#include "livo/import/file_utils.hpp"
#include "livo/import/rosbag2_import.hpp"
#include "livo/import/rosbag_presets.hpp"

namespace livo::import {

namespace {

LidarStampConvention stampConvention(const std::string& s) {
  if (s == "start") return LidarStampConvention::kStart;
  if (s == "end") return LidarStampConvention::kEnd;
  throw std::invalid_argument("--lidar-stamp: expected start or end, got '" + s + "'");
}

KittiPointFields pointFields(const std::string& s) {
  if (s == "auto") return KittiPointFields::kAuto;
  if (s == "xyzi") return KittiPointFields::kXyzi;
  if (s == "xyz") return KittiPointFields::kXyz;
  throw std::invalid_argument("--point-fields: expected auto, xyzi or xyz, got '" + s + "'");
}

/// The --*-channel flags over `names`.
ChannelNames channelFlags(const CommandLine& cli, ChannelNames names) {
  auto channel = [&](const char* flag, std::string& name) {
    if (cli.has(flag)) name = cli.get(flag);
  };
  channel("--imu-channel", names.imu);
  channel("--lidar-channel", names.lidar);
  channel("--camera-channel", names.camera);
  channel("--camera-right-channel", names.camera_right);
  channel("--depth-channel", names.depth);
  channel("--ground-truth-channel", names.ground_truth);
  return names;
}

/// The rosbag flags a preset does not override: topics (a --ground-truth that names no file and
/// starts with '/' is a topic), topic auto-mapping, stamps and IMU units.
RosbagImportOptions rosbagFlags(const CommandLine& cli, const std::string& format) {
  RosbagImportOptions r;
  r.imu_topic = cli.get("--imu");
  r.lidar_topic = cli.get("--lidar");
  r.camera_topic = cli.get("--camera");
  r.camera_right_topic = cli.get("--camera-right");
  r.depth_topic = cli.get("--depth");
  r.camera_info_topic = cli.get("--camera-info");
  if (cli.has("--ground-truth")) {
    const std::string gt = cli.get("--ground-truth");
    if ((format == "rosbag" || format == "rosbag2") && !gt.empty() && gt[0] == '/' && !isFile(gt))
      r.ground_truth_topic = gt;
    else
      r.ground_truth_file = gt;
  }
  r.ground_truth_tf_frame = cli.get("--ground-truth-frame");
  r.auto_map = !cli.has("--no-auto-topics");
  r.use_bag_time = cli.has("--use-bag-time");
  r.imu_units.accel = cli.get("--imu-accel-unit");
  r.imu_units.gyro = cli.get("--imu-gyro-unit");
  return r;
}

/// The LiDAR flags over `lidar` (what a preset set).
PointCloudConversionOptions lidarFlags(const CommandLine& cli, PointCloudConversionOptions lidar) {
  if (cli.has("--lidar-stamp")) lidar.stamp = stampConvention(cli.get("--lidar-stamp"));
  if (cli.has("--sweep-duration")) lidar.sweep_duration = cli.getDouble("--sweep-duration");
  if (cli.has("--lidar-rings")) lidar.num_rings = static_cast<int>(cli.getInt("--lidar-rings"));
  lidar.time_field = cli.get("--lidar-time-field");
  lidar.time_unit = cli.get("--lidar-time-unit");
  lidar.azimuth_times = !cli.has("--no-azimuth-times");
  return lidar;
}

EurocImportOptions eurocFlags(const CommandLine& cli) {
  EurocImportOptions e;
  if (cli.has("--ground-truth")) e.ground_truth_file = cli.get("--ground-truth");
  e.decode_png = cli.has("--decode-png");
  return e;
}

OusterImportOptions ousterFlags(const CommandLine& cli) {
  OusterImportOptions o;
  o.metadata_file = cli.get("--metadata");
  o.keep_partial_sweeps = !cli.has("--drop-partial-sweeps");
  return o;
}

KittiImportOptions kittiFlags(const CommandLine& cli) {
  KittiImportOptions k;
  if (cli.has("--sweep-duration")) k.sweep_duration = cli.getDouble("--sweep-duration");
  k.poses_file = cli.get("--poses");
  k.times_file = cli.get("--times");
  k.lidar_rate_hz = cli.getDouble("--lidar-rate");
  k.point_fields = pointFields(cli.get("--point-fields"));
  return k;
}

}  // namespace

ImportJob importJobFromCommandLine(const CommandLine& cli) {
  ImportJob job;
  job.format = cli.get("FORMAT");
  job.input = cli.get("INPUT");
  if (!cli.has("--out")) throw std::invalid_argument("--out LOG is required");
  job.out = cli.get("--out");
  job.preset = cli.get("--preset");
  if (cli.has("--rig")) {
    job.rig_file = cli.get("--rig");
    job.rig = readSensorRig(Config::load(job.rig_file).section("rig"));
    job.channels = channelNamesOf(*job.rig, job.channels);
  }
  job.rig_out = cli.get("--rig-out");
  job.channels = channelFlags(cli, job.channels);
  job.max_buffer_mb = cli.getInt("--max-buffer-mb");
  job.quiet = cli.has("--quiet");
  job.rosbag = rosbagFlags(cli, job.format);
  job.euroc = eurocFlags(cli);
  applyPreset(job);  // fills what the flags left empty
  job.rosbag.lidar = lidarFlags(cli, job.rosbag.lidar);
  job.ouster = ousterFlags(cli);
  job.kitti = kittiFlags(cli);
  return job;
}

void printRosbagPresets(std::ostream& out) {
  for (const RosbagPreset& p : rosbagPresets()) out << p.name << ": " << p.description << "\n";
}

void printBagTopics(const std::string& format, const std::string& bag, std::ostream& out) {
  if (format != "rosbag" && format != "rosbag2")
    throw std::invalid_argument("--list-topics is for the rosbag and rosbag2 formats");
  for (const BagTopic& t : format == "rosbag2" ? listRosbag2Topics(bag) : listBagTopics(bag)) out << t.topic << "  " << t.type << "  " << t.messages << "\n";
}

}  // namespace livo::import
