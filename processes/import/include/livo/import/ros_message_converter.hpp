// One conversion path for ROS messages, from a bag or live: a serialised message (ROS 1
// serialisation from a ROS 1 bag or a ROS 1 subscription, CDR from a ROS 2 bag) is decoded into
// the plain structs of ros_messages.hpp, then converted to the project's types by the same code
// whatever the format: topic roles (--imu, --lidar, ... and their automatic choice), stamps (header
// or receive time), IMU units, PointCloud2 / Image / CompressedImage / depth conversion, CameraInfo
// calibration, ground-truth poses, and the report's skips. The converted messages go to a
// MessageObserver: livo-import's SortedLogWriter (through LogWriterSink), livo-ros-bridge's LCM queue.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "livo/import/import_report.hpp"
#include "livo/import/imu_units.hpp"
#include "livo/import/ros_messages.hpp"
#include "livo/import/rosbag_import.hpp"
#include "livo/import/sorted_log_writer.hpp"
#include "livo/imu_t.hpp"
#include "livo/pose_t.hpp"

namespace livo::import {

enum class RosWireFormat { kRos1, kCdr };

/// A serialised message as a bag holds it (or a subscription delivers it). The strings are the
/// caller's (not copied).
struct RosWireMessage {
  const std::string* topic = nullptr;
  const std::string* type = nullptr;    // "sensor_msgs/Imu" or "sensor_msgs/msg/Imu"
  const std::string* md5sum = nullptr;  // ROS 1 only (nullptr: not checked)
  RosWireFormat format = RosWireFormat::kRos1;
  int64_t receive_time_ns = 0;  // the bag's receive (log) time, or the arrival time
  const uint8_t* data = nullptr;
  size_t size = 0;
  std::string where;  // "<file>: message record 12 (topic /imu)", for errors
};

/// A topic and its type, as a bag's connections or metadata list them.
struct RosTopic {
  std::string topic, type;
};

/// sensor_msgs/Imu -> imu_t at `utime` (no unit conversion; ImuUnitNormaliser does that).
imu_t imuFromRos(const RosImu& m, int64_t utime);
/// A stamped pose -> pose_t W -> `child_frame` at `utime` (identity orientation if it has none).
pose_t poseFromRos(const RosStampedPose& p, int64_t utime, const std::string& child_frame);

/// The encoding of each sensor_msgs/Image topic's first message: whether a topic is depth is in
/// its messages, not its type. Offer messages until done().
class FirstImageEncodings {
 public:
  explicit FirstImageEncodings(const std::vector<RosTopic>& topics);
  void offer(const RosWireMessage& m);
  bool done() const { return encodings_.size() == image_topics_.size(); }
  const std::map<std::string, std::string>& encodings() const { return encodings_; }

 private:
  std::set<std::string> image_topics_;
  std::map<std::string, std::string> encodings_;
};

class RosMessageConverter {
 public:
  /// `sink` gets each converted message with its LCM channel (o.channels), in conversion order;
  /// `r` gets the notes, metadata and skips. Neither is owned. `receive_time` names
  /// RosWireMessage::receive_time_ns in the report ("the arrival time" for a live input).
  RosMessageConverter(const RosbagImportOptions& o, MessageObserver& sink, ImportReport& r,
                      std::string receive_time = "the bag's receive time");

  /// Fills empty roles from the bag's topics when exactly one topic fits. `image_encodings`
  /// (FirstImageEncodings) tells depth Image topics, which fit only the depth role, from cameras.
  void autoMap(const std::vector<RosTopic>& topics, const std::map<std::string, std::string>& image_encodings);
  /// Decodes and converts one message. Returns false, with the reason in the report's skips, if
  /// it was refused: topic not mapped, unknown type, other md5sum, a type that cannot fill the
  /// topic's role, undecodable bytes. (A decoded message may still be skipped, e.g. a non-finite
  /// IMU sample, or held back, e.g. IMU samples until their units are decided.)
  bool handle(const RosWireMessage& m);
  /// Flushes what is held back (IMU samples waiting for the unit decision).
  void finish();
  /// (role name, topic) of each role with a topic: imu, lidar, camera, ...
  std::vector<std::pair<std::string, std::string>> roleTopics() const;

 private:
  enum class Role { kIgnored, kImu, kLidar, kCamera, kCameraRight, kDepth, kCameraInfo, kGroundTruth };
  static const char* roleName(Role r);
  void autoMapCameraInfo(const std::vector<RosTopic>& topics);
  Role roleOf(const std::string& topic) const;
  static std::string frameOf(Role role) { return role == Role::kCameraRight ? "C1" : "C"; }
  int64_t stampOf(const RosHeader& h, const RosWireMessage& m);
  template <class Reader>
  void decodeAndConvert(Reader& r, const RosTypeInfo& info, Role role, const RosWireMessage& m);
  void imu(const RosImu& msg, const RosWireMessage& m);
  void cloud(RosPointCloud2 msg, const RosWireMessage& m);
  void image(Role role, image_t img, const RosWireMessage& m);
  void cameraInfo(const RosCameraInfo& msg, const std::string& topic);
  void pose(const RosStampedPose& p, const RosWireMessage& m);
  void transforms(const std::vector<RosStampedPose>& tfs, const RosWireMessage& m);

  const RosbagImportOptions& options_;
  MessageObserver& sink_;
  ImportReport& report_;
  std::string receive_time_;
  std::map<Role, std::string> topics_;
  std::map<std::string, std::unique_ptr<ImuUnitNormaliser>> imu_units_;
  int64_t camera_infos_ = 0;
  RosCameraInfo first_camera_info_;
  bool camera_info_changed_ = false;
  std::string tf_frame_;  // the ground truth's child frame on a TFMessage topic
};

}  // namespace livo::import
