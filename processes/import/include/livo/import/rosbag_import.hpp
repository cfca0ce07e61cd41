// ROS 1 bag -> LCM log: each mapped topic's messages converted to the project's types
// (sensor_msgs/Imu -> imu_t, PointCloud2 -> point_cloud_t, Image / CompressedImage -> image_t,
// depth Image (16UC1 mm, 32FC1 m) -> image_t DEPTH16 / DEPTH32F,
// Odometry / PoseStamped / PoseWithCovarianceStamped / TransformStamped / PointStamped, and one
// child frame's transforms of a tf2_msgs/TFMessage topic -> pose_t),
// stamped by their header stamps. The camera's sensor_msgs/CameraInfo is read into the report's
// calibration (no message type carries it). Other topics are counted, never decoded.
#pragma once

#include <string>
#include <vector>

#include "livo/import/channel_names.hpp"
#include "livo/import/import_report.hpp"
#include "livo/import/imu_units.hpp"
#include "livo/import/point_cloud2_conversion.hpp"
#include "livo/import/sorted_log_writer.hpp"

namespace livo::import {

struct RosbagImportOptions {
  // Topics; empty ones are chosen automatically when the bag has exactly one topic of the type
  // (IMU, PointCloud2, image, depth image) and `auto_map` is set. An Image topic whose first
  // message is 16UC1 or 32FC1 is depth, never a camera.
  std::string imu_topic, lidar_topic, camera_topic, camera_right_topic, depth_topic, ground_truth_topic;
  // The camera's sensor_msgs/CameraInfo; empty: the bag's only CameraInfo topic, or with several
  // the one in the camera topic's namespace (/a/b/image_raw -> /a/b/camera_info).
  std::string camera_info_topic;
  bool auto_map = true;
  std::string ground_truth_file;  // TUM / EuRoC csv instead of a topic
  std::string ground_truth_child_frame = "I";
  // A tf2_msgs/TFMessage ground-truth topic (/tf): the child frame whose transforms are the ground
  // truth; empty: the child frame of the topic's first transform (said in a note).
  std::string ground_truth_tf_frame;
  ChannelNames channels;
  PointCloudConversionOptions lidar;
  ImuUnitOptions imu_units;
  bool use_bag_time = false;  // stamp by the bag's receive time, not header.stamp
  bool progress = true;
};

/// Reads the whole bag (all bags, in order). A read error stops that bag; what was read is kept
/// and the error is in the report.
void importRosbag(const std::vector<std::string>& bags, const RosbagImportOptions& options, SortedLogWriter& writer,
                  ImportReport& report);

/// Topics of a bag with type and message count (reads the whole bag), for --list-topics.
struct BagTopic {
  std::string topic, type;
  int64_t messages = 0;
};
std::vector<BagTopic> listBagTopics(const std::string& bag);

}  // namespace livo::import
