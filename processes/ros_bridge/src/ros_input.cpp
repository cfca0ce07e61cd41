#include "livo/ros_bridge/ros_input.hpp"

#include <cmath>

#include "livo/import/image_encoding.hpp"
#include "livo/import/point_cloud2_conversion.hpp"
#include "livo/import/ros_message_converter.hpp"
#include "livo/import/ros_messages.hpp"
#include "livo/import/stamp_conversion.hpp"

namespace livo::ros_bridge {

using import::RosMessageKind;

const char* roleName(SensorRole role) {
  switch (role) {
    case SensorRole::kImu: return "imu";
    case SensorRole::kLidar: return "lidar";
    case SensorRole::kCamera: return "camera";
    case SensorRole::kCameraRight: return "camera-right";
    case SensorRole::kDepth: return "depth";
    case SensorRole::kGroundTruth: return "ground-truth";
  }
  return "?";
}

std::map<std::string, SensorRole> topicRoles(const import::RosbagImportOptions& o) {
  std::map<std::string, SensorRole> roles;
  auto add = [&](const std::string& topic, SensorRole role) {
    if (!topic.empty()) roles.emplace(topic, role);
  };
  add(o.imu_topic, SensorRole::kImu);
  add(o.lidar_topic, SensorRole::kLidar);
  add(o.camera_topic, SensorRole::kCamera);
  add(o.camera_right_topic, SensorRole::kCameraRight);
  add(o.depth_topic, SensorRole::kDepth);
  add(o.ground_truth_topic, SensorRole::kGroundTruth);
  return roles;
}

namespace {

/// Which roles a message kind can fill (as livo-import rosbag's topic roles).
bool fits(SensorRole role, RosMessageKind kind) {
  switch (role) {
    case SensorRole::kImu: return kind == RosMessageKind::kImu;
    case SensorRole::kLidar: return kind == RosMessageKind::kPointCloud2;
    case SensorRole::kCamera:
    case SensorRole::kCameraRight: return kind == RosMessageKind::kImage || kind == RosMessageKind::kCompressedImage;
    case SensorRole::kDepth: return kind == RosMessageKind::kImage;
    case SensorRole::kGroundTruth: return kind == RosMessageKind::kPose || kind == RosMessageKind::kTfMessage;
  }
  return false;
}

std::string frameOf(SensorRole role) { return role == SensorRole::kCameraRight ? "C1" : "C"; }

void setHeaderStamp(import::RosHeader& h, int64_t ns) {
  h.sec = static_cast<uint32_t>(ns / 1000000000LL);
  h.nsec = static_cast<uint32_t>(ns % 1000000000LL);
}

}  // namespace

RosInputConverter::RosInputConverter(const import::RosbagImportOptions& options, import::MessageObserver& sink,
                                     import::ImportReport& report)
    : options_(options), sink_(sink), report_(report) {}

bool RosInputConverter::convert(SensorRole role, const RosMessageBytes& m) {
  const std::string where = "topic " + m.topic;
  const import::RosTypeInfo info = import::rosTypeInfo(m.type);
  if (info.kind == RosMessageKind::kUnsupported) {
    report_.skip("unsupported message type " + m.type + " on " + m.topic, where);
    return false;
  }
  if (m.md5 != info.md5 && m.md5 != "*") {
    report_.skip(
        "md5sum " + m.md5 + " of " + m.type + " on " + m.topic + " differs from the known definition " + info.md5,
        where);
    return false;
  }
  if (!fits(role, info.kind)) {
    report_.skip("topic " + m.topic + " is " + m.type + ", which cannot be the " + roleName(role), where);
    return false;
  }
  import::ByteReader r(m.data, m.size, where);
  try {
    switch (info.kind) {
      case RosMessageKind::kImu: imu(import::decodeRosImu(r), m, where); break;
      case RosMessageKind::kPointCloud2: cloud(import::decodeRosPointCloud2(r), m, where); break;
      case RosMessageKind::kImage: {
        const import::RosImage msg = import::decodeRosImage(r);
        image(role, role == SensorRole::kDepth ? import::convertRosDepthImage(msg, frameOf(role), where)
                                               : import::convertRosImage(msg, frameOf(role), where));
        break;
      }
      case RosMessageKind::kCompressedImage:
        image(role, import::convertRosCompressedImage(import::decodeRosCompressedImage(r), frameOf(role), where));
        break;
      case RosMessageKind::kPose: pose(info.decode_pose(r), m, where); break;
      case RosMessageKind::kTfMessage: transforms(import::decodeRosTfMessage(r), m, where); break;
      default: return false;
    }
  } catch (const import::DecodeError& e) {
    std::string what = e.what();
    if (what.rfind(where + ": ", 0) == 0) what = what.substr(where.size() + 2);
    report_.skip("undecodable " + m.type + " on " + m.topic + ": " + what, e.what());
    return false;
  }
  return true;
}

void RosInputConverter::flush() {
  for (auto& kv : imu_units_) kv.second->flush();
}

int64_t RosInputConverter::stampOf(const import::RosHeader& h, const RosMessageBytes& m, const std::string& where) {
  if (h.sec == 0 && h.nsec == 0) {
    report_.skip("header.stamp is zero: stamped with the arrival time instead", where, 1, false);
    return import::nsToUtime(m.receive_ns);
  }
  return import::nsToUtime(h.stampNs());
}

void RosInputConverter::imu(const import::RosImu& msg, const RosMessageBytes& m, const std::string& where) {
  for (double v : msg.angular_velocity)
    if (!std::isfinite(v)) return report_.skip("non-finite angular_velocity", where);
  for (double v : msg.linear_acceleration)
    if (!std::isfinite(v)) return report_.skip("non-finite linear_acceleration", where);
  const imu_t s = import::imuFromRos(msg, stampOf(msg.header, m, where));
  auto& units = imu_units_[m.topic];
  if (!units) {
    const std::string channel = options_.channels.imu;
    units = std::make_unique<import::ImuUnitNormaliser>(options_.imu_units, m.topic, report_,
                                                        [this, channel](const imu_t& x) { sink_.observe(channel, x); });
  }
  units->add(s);
}

void RosInputConverter::cloud(import::RosPointCloud2 msg, const RosMessageBytes& m, const std::string& where) {
  if (msg.header.sec == 0 && msg.header.nsec == 0) {
    report_.skip("header.stamp is zero: stamped with the arrival time instead", where, 1, false);
    setHeaderStamp(msg.header, m.receive_ns);
  }
  const import::PointCloudConversion c = import::convertPointCloud2(msg, options_.lidar, where);
  if (c.non_finite_points) report_.skip("LiDAR points with a NaN/inf coordinate", where, c.non_finite_points, false);
  if (c.zero_points) report_.skip("LiDAR points at (0, 0, 0) (no return)", where, c.zero_points, false);
  if (report_.metadataValue("lidar_point_layout").empty()) {
    report_.metadataString("lidar_point_layout", c.layout);
    report_.metadataString("lidar_topic", m.topic);
  }
  sink_.observe(options_.channels.lidar, c.cloud);
}

void RosInputConverter::image(SensorRole role, image_t img) {
  sink_.observe(role == SensorRole::kCameraRight ? options_.channels.camera_right
                : role == SensorRole::kDepth     ? options_.channels.depth
                                                 : options_.channels.camera,
                img);
}

void RosInputConverter::pose(const import::RosStampedPose& p, const RosMessageBytes& m, const std::string& where) {
  sink_.observe(options_.channels.ground_truth,
                import::poseFromRos(p, stampOf(p.header, m, where), options_.ground_truth_child_frame));
}

void RosInputConverter::transforms(const std::vector<import::RosStampedPose>& tfs, const RosMessageBytes& m,
                                   const std::string& where) {
  for (const import::RosStampedPose& t : tfs) {
    if (tf_frame_.empty()) {
      tf_frame_ = options_.ground_truth_tf_frame.empty() ? t.child_frame_id : options_.ground_truth_tf_frame;
      if (options_.ground_truth_tf_frame.empty())
        report_.note("ground_truth_frame not given: the ground truth is " + m.topic + "'s transforms to " + tf_frame_ +
                     " (the first child frame on it)");
    }
    if (t.child_frame_id == tf_frame_)
      pose(t, m, where);
    else
      report_.skip("transforms on " + m.topic + " to another frame than " + tf_frame_ + " (ground_truth_frame)", where,
                   1, false);
  }
}

}  // namespace livo::ros_bridge
