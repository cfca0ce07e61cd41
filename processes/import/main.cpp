// livo-import FORMAT INPUT --out LOG [--preset NAME] [--rig-out FILE] [--rig FILE]: dataset formats -> the
// project's LCM log (exit 0; 1 an input not read to its end; 2 usage or a bad --rig; 3 the log does not fit --rig).
#include <iostream>

#include "livo/command_line.hpp"
#include "livo/import/import_command_line.hpp"

namespace {

livo::CommandLine importCommandLine() {
  livo::CommandLine cli(
      "livo-import",
      "Turns a dataset into an LCM log of the project's types (IMU, LIDAR, CAMERA, CAMERA_RIGHT, "
      "DEPTH, GROUND_TRUTH), sorted by time, with a <log>.meta.yaml sidecar. See processes/import/README.md.");
  cli.positional("FORMAT",
                 "rosbag (ROS 1 bag), rosbag2 (ROS 2 bag: directory with metadata.yaml, .mcap or .db3; the "
                 "rosbag options apply), kitti (raw drive / odometry / scan folder), euroc (ASL folder), "
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
              "PointStamped, TFMessage) or a TUM / EuRoC csv file; euroc: a TUM / csv file")
      .option("--ground-truth-frame", "CHILD",
              "rosbag: a tf2_msgs/TFMessage ground-truth topic's child frame to take (default: its first)")
      .flag("--no-auto-topics",
            "rosbag: do not pick the only IMU / PointCloud2 / image / depth image topic when none is given")
      .flag("--list-topics", "rosbag, rosbag2: print the bag's topics, types and counts, then exit")
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
  return cli;
}

}  // namespace

int main(int argc, char** argv) {
  livo::CommandLine cli = importCommandLine();
  if (!cli.parse(argc, argv)) return cli.exitCode();
  if (cli.has("--list-presets")) {
    livo::import::printRosbagPresets(std::cout);
    return 0;
  }
  livo::import::ImportJob job;
  try {
    if (cli.has("--list-topics")) {
      livo::import::printBagTopics(cli.get("FORMAT"), cli.get("INPUT"), std::cout);
      return 0;
    }
    job = livo::import::importJobFromCommandLine(cli);
  } catch (const std::exception& e) {
    std::cerr << "livo-import: " << e.what() << "\n";
    return 2;
  }
  const livo::import::ImportOutcome outcome = livo::import::runImport(job, &std::cout);
  if (!outcome.ok()) return 1;
  return outcome.rigFits() ? 0 : 3;
}
