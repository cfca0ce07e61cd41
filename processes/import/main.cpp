// livo-import FORMAT INPUT --out LOG [--preset NAME] [--rig-out FILE] [--rig FILE]: dataset formats -> the
// project's LCM log (exit 0; 1 an input not read to its end; 2 usage or a bad --rig; 3 the log does not fit --rig).
#include <iostream>

#include "livo/command_line.hpp"
#include "livo/config.hpp"
#include "livo/import/file_utils.hpp"
#include "livo/import/import_job.hpp"
#include "livo/import/rosbag_presets.hpp"

namespace {

livo::import::LidarStampConvention stampConvention(const std::string& s) {
  if (s == "start") return livo::import::LidarStampConvention::kStart;
  if (s == "end") return livo::import::LidarStampConvention::kEnd;
  throw std::invalid_argument("--lidar-stamp: expected start or end, got '" + s + "'");
}

livo::import::KittiPointFields pointFields(const std::string& s) {
  if (s == "auto") return livo::import::KittiPointFields::kAuto;
  if (s == "xyzi") return livo::import::KittiPointFields::kXyzi;
  if (s == "xyz") return livo::import::KittiPointFields::kXyz;
  throw std::invalid_argument("--point-fields: expected auto, xyzi or xyz, got '" + s + "'");
}

}  // namespace

int main(int argc, char** argv) {
  livo::CommandLine cli(
      "livo-import",
      "Turns a dataset into an LCM log of the project's types (IMU, LIDAR, CAMERA, CAMERA_RIGHT, "
      "DEPTH, GROUND_TRUTH), sorted by time, with a <log>.meta.yaml sidecar. See processes/import/README.md.");
  cli.positional("FORMAT",
                 "rosbag (ROS 1 bag), kitti (raw drive / odometry / scan folder), euroc (ASL folder), "
                 "ouster (pcap + metadata JSON)");
  cli.positional("INPUT", "the bag, folder or pcap file");
  cli.option("--out", "LOG", "output LCM log (required unless --list-topics)")
      .option("--preset", "NAME", "rosbag topic map and conventions: ntu_viral, m2dgr (--list-presets)")
      .option("--imu", "TOPIC", "rosbag: IMU topic (sensor_msgs/Imu)")
      .option("--lidar", "TOPIC", "rosbag: LiDAR topic (sensor_msgs/PointCloud2)")
      .option("--camera", "TOPIC", "rosbag: camera topic (sensor_msgs/Image or CompressedImage)")
      .option("--camera-right", "TOPIC", "rosbag: second camera topic")
      .option("--depth", "TOPIC",
              "rosbag: depth image topic registered to the camera (sensor_msgs/Image 16UC1 mm or 32FC1 m)")
      .option(
          "--camera-info", "TOPIC",
          "rosbag: the camera's sensor_msgs/CameraInfo (default: the only one, or the one in the camera's namespace); "
          "read for --rig-out, --rig and the sidecar")
      .option("--ground-truth", "TOPIC|FILE",
              "rosbag: ground-truth topic (Odometry, PoseStamped, PoseWithCovarianceStamped, TransformStamped, "
              "PointStamped) or a TUM / EuRoC csv file; euroc: a TUM / csv file")
      .flag("--no-auto-topics",
            "rosbag: do not pick the only IMU / PointCloud2 / image / depth image topic when none is given")
      .flag("--list-topics", "rosbag: print the bag's topics, types and counts, then exit")
      .flag("--list-presets", "print the presets, then exit")
      .option("--rig-out", "FILE",
              "also write a starter rig config (YAML) from what the input told: channels, measured rates, LiDAR "
              "rings and model, camera size, colour and calibration; REPLACE: marks what it could not tell")
      .option("--rig", "FILE",
              "the rig config the log is for: its channel names are written (unless a --*-channel flag says "
              "otherwise) and the log is checked against it (camera size, sensors, channels: errors, exit 3; "
              "intrinsics, rates, rings: warnings)")
      .option("--imu-channel", "NAME", "IMU channel (default IMU, or the --rig's)")
      .option("--lidar-channel", "NAME", "LiDAR channel (default LIDAR, or the --rig's)")
      .option("--camera-channel", "NAME", "camera channel (default CAMERA, or the --rig's)")
      .option("--camera-right-channel", "NAME", "second camera channel", "CAMERA_RIGHT")
      .option("--depth-channel", "NAME", "depth image channel (default DEPTH, or the --rig's)")
      .option("--ground-truth-channel", "NAME", "ground-truth channel (default GROUND_TRUTH, or the --rig's)")
      .option("--lidar-stamp", "start|end", "rosbag: what a cloud's header stamp marks (preset or start)")
      .option("--sweep-duration", "S", "sweep length in seconds (rosbag, kitti; default 0.1)")
      .option("--lidar-rings", "N", "rosbag: beams of the LiDAR (default: from the cloud)")
      .option("--lidar-time-field", "NAME", "rosbag: per-point time field (default: time, t, offset_time, timestamp)")
      .option("--lidar-time-unit", "s|ms|us|ns", "rosbag: unit of the time field (default: ns if integer, s if float)")
      .flag("--no-azimuth-times",
            "rosbag: a spinning LiDAR's cloud without a time field keeps every point at the sweep start (default: "
            "times from the azimuth)")
      .option("--imu-accel-unit", "auto|m/s2|g", "rosbag: acceleration unit", "auto")
      .option("--imu-gyro-unit", "rad/s|deg/s", "rosbag: angular rate unit", "rad/s")
      .flag("--use-bag-time", "rosbag: stamp messages with the bag's receive time instead of header.stamp")
      .flag("--decode-png", "euroc: decode PNG images to GRAY8 instead of keeping them compressed")
      .option("--metadata", "FILE", "ouster: sensor metadata JSON (default: beside the pcap)")
      .flag("--drop-partial-sweeps", "ouster: drop sweeps that miss packets")
      .option("--poses", "FILE", "kitti: odometry poses file (default: ../../poses/<seq>.txt)")
      .option("--times", "FILE", "kitti: odometry times.txt (default: beside velodyne/)")
      .option("--lidar-rate", "HZ", "kitti: scan rate of a folder without timestamps", "10")
      .option("--point-fields", "auto|xyzi|xyz", "kitti: floats per point in .bin scans", "auto")
      .option("--max-buffer-mb", "MB", "memory for sorting before spilling to temporary files", "512")
      .flag("--quiet", "no progress line and no warnings on stderr (the summary still prints)");
  if (!cli.parse(argc, argv)) return cli.exitCode();

  if (cli.has("--list-presets")) {
    for (const livo::import::RosbagPreset& p : livo::import::rosbagPresets())
      std::cout << p.name << ": " << p.description << "\n";
    return 0;
  }
  livo::import::ImportJob job;
  try {
    job.format = cli.get("FORMAT");
    job.input = cli.get("INPUT");
    if (cli.has("--list-topics")) {
      if (job.format != "rosbag") throw std::invalid_argument("--list-topics is for the rosbag format");
      for (const livo::import::BagTopic& t : livo::import::listBagTopics(job.input))
        std::cout << t.topic << "  " << t.type << "  " << t.messages << "\n";
      return 0;
    }
    if (!cli.has("--out")) throw std::invalid_argument("--out LOG is required");
    job.out = cli.get("--out");
    job.preset = cli.get("--preset");
    if (cli.has("--rig")) {
      job.rig_file = cli.get("--rig");
      job.rig = livo::readSensorRig(livo::Config::load(job.rig_file).section("rig"));
      job.channels = livo::import::channelNamesOf(*job.rig, job.channels);
    }
    job.rig_out = cli.get("--rig-out");
    auto channel = [&](const char* flag, std::string& name) {
      if (cli.has(flag)) name = cli.get(flag);
    };
    channel("--imu-channel", job.channels.imu);
    channel("--lidar-channel", job.channels.lidar);
    channel("--camera-channel", job.channels.camera);
    channel("--camera-right-channel", job.channels.camera_right);
    channel("--depth-channel", job.channels.depth);
    channel("--ground-truth-channel", job.channels.ground_truth);
    job.max_buffer_mb = cli.getInt("--max-buffer-mb");
    job.quiet = cli.has("--quiet");

    livo::import::RosbagImportOptions& r = job.rosbag;
    r.imu_topic = cli.get("--imu");
    r.lidar_topic = cli.get("--lidar");
    r.camera_topic = cli.get("--camera");
    r.camera_right_topic = cli.get("--camera-right");
    r.depth_topic = cli.get("--depth");
    r.camera_info_topic = cli.get("--camera-info");
    if (cli.has("--ground-truth")) {
      const std::string gt = cli.get("--ground-truth");
      if (job.format == "rosbag" && !gt.empty() && gt[0] == '/' && !livo::import::isFile(gt))
        r.ground_truth_topic = gt;
      else
        r.ground_truth_file = gt;
      job.euroc.ground_truth_file = gt;
    }
    r.auto_map = !cli.has("--no-auto-topics");
    r.use_bag_time = cli.has("--use-bag-time");
    r.imu_units.accel = cli.get("--imu-accel-unit");
    r.imu_units.gyro = cli.get("--imu-gyro-unit");
    applyPreset(job);  // fills what the flags left empty
    if (cli.has("--lidar-stamp")) r.lidar.stamp = stampConvention(cli.get("--lidar-stamp"));
    if (cli.has("--sweep-duration")) {
      r.lidar.sweep_duration = cli.getDouble("--sweep-duration");
      job.kitti.sweep_duration = r.lidar.sweep_duration;
    }
    if (cli.has("--lidar-rings")) r.lidar.num_rings = static_cast<int>(cli.getInt("--lidar-rings"));
    r.lidar.time_field = cli.get("--lidar-time-field");
    r.lidar.time_unit = cli.get("--lidar-time-unit");
    r.lidar.azimuth_times = !cli.has("--no-azimuth-times");

    job.euroc.decode_png = cli.has("--decode-png");
    job.ouster.metadata_file = cli.get("--metadata");
    job.ouster.keep_partial_sweeps = !cli.has("--drop-partial-sweeps");
    job.kitti.poses_file = cli.get("--poses");
    job.kitti.times_file = cli.get("--times");
    job.kitti.lidar_rate_hz = cli.getDouble("--lidar-rate");
    job.kitti.point_fields = pointFields(cli.get("--point-fields"));
  } catch (const std::exception& e) {
    std::cerr << "livo-import: " << e.what() << "\n";
    return 2;
  }
  const livo::import::ImportOutcome outcome = livo::import::runImport(job, &std::cout);
  if (!outcome.ok()) return 1;
  return outcome.rigFits() ? 0 : 3;
}
