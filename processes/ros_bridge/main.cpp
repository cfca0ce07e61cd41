// livo-ros-bridge --config FILE [--preset NAME] [--imu T] [--lidar T] [--camera T] ... : ROS 1
// sensor topics into the pipeline (livo-import rosbag's conversions) and its outputs back to ROS.
#include <iostream>

#include <ros/ros.h>

#include "livo/command_line.hpp"
#include "livo/config_check.hpp"
#include "livo/ros_bridge/ros_bridge_node.hpp"

namespace {

livo::ros_bridge::RosBridgeFlags flagsOf(const livo::CommandLine& cli) {
  livo::ros_bridge::RosBridgeFlags f;
  f.preset = cli.get("--preset");
  f.imu = cli.get("--imu");
  f.lidar = cli.get("--lidar");
  f.camera = cli.get("--camera");
  f.camera_right = cli.get("--camera-right");
  f.depth = cli.get("--depth");
  f.ground_truth = cli.get("--ground-truth");
  f.ground_truth_frame = cli.get("--ground-truth-frame");
  f.world_frame = cli.get("--world-frame");
  f.body_frame = cli.get("--body-frame");
  f.lidar_stamp = cli.get("--lidar-stamp");
  if (cli.has("--sweep-duration")) f.sweep_duration = cli.getDouble("--sweep-duration");
  if (cli.has("--lidar-rings")) f.lidar_rings = static_cast<int>(cli.getInt("--lidar-rings"));
  return f;
}

/// Waits for the ROS master (roscpp would retry inside its first advertise, deaf to SIGINT, since
/// the signals are livo's); false if shutdown was requested first.
bool waitForMaster() {
  if (ros::master::check()) return true;
  std::cerr << "livo-ros-bridge: waiting for the ROS master at " << ros::master::getURI() << std::endl;
  while (!livo::shutdownRequested()) {
    if (ros::master::check()) return true;
    ros::WallDuration(0.2).sleep();
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  // ROS's own arguments (__name:=, __ns:=, remappings) are taken out of argv here.
  ros::init(argc, argv, "livo_ros_bridge", ros::init_options::NoSigintHandler);
  livo::CommandLine cli("livo-ros-bridge",
                        "ROS 1 sensor topics -> LCM (livo-import rosbag's conversions); ODOMETRY, REGISTERED_SCAN "
                        "and COLORED_CLOUD -> ROS (nav_msgs/Odometry, /tf, sensor_msgs/PointCloud2).");
  cli.option("--config", "FILE", "project config (rig:, optional ros_bridge:)")
      .option("--name", "NAME", "node name on the LCM bus", "ros_bridge")
      .option("--lcm-url", "URL", "LCM provider (default: LCM_DEFAULT_URL or LCM's default)")
      .option("--preset", "NAME", "livo-import rosbag preset: topics and LiDAR conventions (ntu_viral, m2dgr)")
      .option("--imu", "TOPIC", "sensor_msgs/Imu")
      .option("--lidar", "TOPIC", "sensor_msgs/PointCloud2")
      .option("--camera", "TOPIC", "sensor_msgs/Image or CompressedImage")
      .option("--camera-right", "TOPIC", "second camera")
      .option("--depth", "TOPIC", "depth sensor_msgs/Image (16UC1 mm, 32FC1 m)")
      .option("--ground-truth", "TOPIC", "nav_msgs/Odometry, geometry_msgs/PoseStamped, ..., tf2_msgs/TFMessage")
      .option("--ground-truth-frame", "FRAME", "on a TFMessage topic: the child frame that is the ground truth")
      .option("--lidar-stamp", "start|end", "what the cloud's header.stamp marks")
      .option("--sweep-duration", "S", "seconds per sweep")
      .option("--lidar-rings", "N", "beams (0: from the cloud)")
      .option("--world-frame", "FRAME", "ROS frame of the odometry and the clouds (default world)")
      .option("--body-frame", "FRAME", "ROS frame of the body (default body)")
      .flag("--quiet", "no option summary at start");
  livo::declareConfigCheck(cli);
  if (!cli.parse(argc, argv)) return cli.exitCode();
  if (!cli.has("--config")) {
    std::cerr << "livo-ros-bridge: --config is required\n" << cli.usage();
    return 2;
  }
  try {
    const livo::Config cfg = livo::Config::load(cli.get("--config"));
    const auto options = livo::ros_bridge::readRosBridgeNodeOptions(cfg, flagsOf(cli));
    if (!cli.has("--quiet")) livo::ros_bridge::printOptions(options, std::cerr);
    if (livo::configCheckDone(cli, std::cout)) return 0;
    livo::installSignalHandlers();
    auto lcm = livo::makeLcm(cli.has("--lcm-url") ? cli.get("--lcm-url") : "");
    if (!waitForMaster()) return 0;  // SIGINT / SIGTERM before the master came
    ros::NodeHandle ros_node;
    livo::NodeOptions node_options;
    node_options.name = cli.get("--name");
    livo::ros_bridge::RosBridgeNode node(*lcm, node_options, options, ros_node);
    const int rc = node.run();
    ros::shutdown();
    return rc;
  } catch (const std::exception& e) {
    std::cerr << "livo-ros-bridge: " << e.what() << std::endl;
    return 1;
  }
}
