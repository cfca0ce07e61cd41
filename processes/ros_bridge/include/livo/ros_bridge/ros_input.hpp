// ROS 1 messages in -> the LCM messages livo-import rosbag writes for them. A message comes as
// its serialised bytes (the ROS 1 wire format, which a bag stores too) with its type name and md5
// sum; it is checked, decoded and converted by livo-import's own functions (rosTypeInfo and the
// decoders of ros_messages.hpp, convertPointCloud2, convertRosImage / convertRosDepthImage /
// convertRosCompressedImage, imuFromRos, ImuUnitNormaliser, poseFromRos), called as livo-import's
// RosMessageConverter calls them, so a topic bridged live and the same topic imported from a bag
// give the same messages (RosBridge.BagThroughRosEqualsImport checks them byte for byte). What is
// left here is that converter's dispatch, which it keeps private and ties to a log writer.
// No ROS library here: the bytes may come from roscpp, a bag or a test.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "livo/import/import_report.hpp"
#include "livo/import/imu_units.hpp"
#include "livo/import/rosbag_import.hpp"
#include "livo/import/sorted_log_writer.hpp"

namespace livo::ros_bridge {

/// What a bridged topic is to the pipeline (livo-import rosbag's --imu, --lidar, ... roles).
enum class SensorRole { kImu, kLidar, kCamera, kCameraRight, kDepth, kGroundTruth };
const char* roleName(SensorRole role);

/// One serialised ROS 1 message as it arrived.
struct RosMessageBytes {
  std::string topic;
  std::string type;  // e.g. sensor_msgs/Imu
  std::string md5;   // the publisher's md5sum of the definition ("*": any)
  const uint8_t* data = nullptr;
  size_t size = 0;
  int64_t receive_ns = 0;  // arrival time: the stamp of a message whose header.stamp is zero
};

/// The bridge's topics with their roles, from livo-import's options (empty topics left out).
std::map<std::string, SensorRole> topicRoles(const import::RosbagImportOptions& options);

class RosInputConverter {
 public:
  /// `sink` gets each converted message with its LCM channel (options.channels); `report` counts
  /// what was refused and why, as an import's report does. Neither is owned.
  RosInputConverter(const import::RosbagImportOptions& options, import::MessageObserver& sink,
                    import::ImportReport& report);

  /// Converts one message of a topic with role `role`. A message that does not convert (unknown
  /// type, other md5, a type that cannot fill the role, undecodable bytes) is skipped in the
  /// report with the reason; nothing reaches the sink. Returns whether it was converted.
  bool convert(SensorRole role, const RosMessageBytes& message);

  /// Emits the IMU samples held while the IMU's units are decided (ImuUnitNormaliser). Call at the end.
  void flush();

 private:
  void imu(const import::RosImu& msg, const RosMessageBytes& m, const std::string& where);
  void cloud(import::RosPointCloud2 msg, const RosMessageBytes& m, const std::string& where);
  void image(SensorRole role, image_t img);
  void pose(const import::RosStampedPose& p, const RosMessageBytes& m, const std::string& where);
  /// tf2_msgs/TFMessage ground truth: the transforms to one child frame (options.ground_truth_tf_frame,
  /// else the first one seen), as the importer takes them.
  void transforms(const std::vector<import::RosStampedPose>& tfs, const RosMessageBytes& m, const std::string& where);
  int64_t stampOf(const import::RosHeader& h, const RosMessageBytes& m, const std::string& where);

  import::RosbagImportOptions options_;
  import::MessageObserver& sink_;
  import::ImportReport& report_;
  std::map<std::string, std::unique_ptr<import::ImuUnitNormaliser>> imu_units_;  // per IMU topic
  std::string tf_frame_;  // the ground truth's child frame on a TFMessage topic, once known
};

}  // namespace livo::ros_bridge
