#include "livo/import/ros_message_converter.hpp"

#include <cmath>
#include <optional>
#include <utility>

#include "livo/import/image_encoding.hpp"
#include "livo/import/point_cloud2_conversion.hpp"
#include "livo/import/stamp_conversion.hpp"

namespace livo::import {

imu_t imuFromRos(const RosImu& m, int64_t utime) {
  imu_t s;
  s.utime = utime;
  for (int i = 0; i < 3; ++i) {
    s.angular_velocity[i] = m.angular_velocity[i];
    s.linear_acceleration[i] = m.linear_acceleration[i];
  }
  return s;
}

pose_t poseFromRos(const RosStampedPose& p, int64_t utime, const std::string& child_frame) {
  pose_t out;
  out.utime = utime;
  out.parent_frame = "W";
  out.child_frame = child_frame;
  for (int i = 0; i < 3; ++i) out.position[i] = p.position[i];
  out.orientation[0] = p.orientation_xyzw[3];
  out.orientation[1] = p.orientation_xyzw[0];
  out.orientation[2] = p.orientation_xyzw[1];
  out.orientation[3] = p.orientation_xyzw[2];
  return out;
}

FirstImageEncodings::FirstImageEncodings(const std::vector<RosTopic>& topics) {
  for (const RosTopic& t : topics)
    if (rosTypeInfo(t.type).kind == RosMessageKind::kImage) image_topics_.insert(t.topic);
}

void FirstImageEncodings::offer(const RosWireMessage& m) {
  const std::string& topic = *m.topic;
  if (!image_topics_.count(topic) || encodings_.count(topic)) return;
  if (rosTypeInfo(*m.type).kind != RosMessageKind::kImage) return;
  try {
    if (m.format == RosWireFormat::kCdr) {
      CdrReader r(m.data, m.size, m.where);
      encodings_[topic] = decodeCdrImage(r).encoding;
    } else {
      ByteReader r(m.data, m.size, m.where);
      encodings_[topic] = decodeRosImage(r).encoding;
    }
  } catch (const DecodeError&) {
    // the import reports it
  }
}

const char* RosMessageConverter::roleName(Role r) {
  switch (r) {
    case Role::kImu: return "imu";
    case Role::kLidar: return "lidar";
    case Role::kCamera: return "camera";
    case Role::kCameraRight: return "camera-right";
    case Role::kDepth: return "depth";
    case Role::kCameraInfo: return "camera-info";
    case Role::kGroundTruth: return "ground-truth";
    default: return "ignored";
  }
}

namespace {

/// Which roles a message kind can fill (Role is the converter's private enum).
template <class Role>
bool fits(Role role, RosMessageKind kind) {
  switch (role) {
    case Role::kImu: return kind == RosMessageKind::kImu;
    case Role::kLidar: return kind == RosMessageKind::kPointCloud2;
    case Role::kCamera:
    case Role::kCameraRight: return kind == RosMessageKind::kImage || kind == RosMessageKind::kCompressedImage;
    case Role::kDepth: return kind == RosMessageKind::kImage;
    case Role::kCameraInfo: return kind == RosMessageKind::kCameraInfo;
    case Role::kGroundTruth: return kind == RosMessageKind::kPose || kind == RosMessageKind::kTfMessage;
    default: return false;
  }
}

}  // namespace

RosMessageConverter::RosMessageConverter(const RosbagImportOptions& o, MessageObserver& sink, ImportReport& r,
                                         std::string receive_time)
    : options_(o), sink_(sink), report_(r), receive_time_(std::move(receive_time)) {
  topics_[Role::kImu] = o.imu_topic;
  topics_[Role::kLidar] = o.lidar_topic;
  topics_[Role::kCamera] = o.camera_topic;
  topics_[Role::kCameraRight] = o.camera_right_topic;
  topics_[Role::kDepth] = o.depth_topic;
  topics_[Role::kCameraInfo] = o.camera_info_topic;
  topics_[Role::kGroundTruth] = o.ground_truth_file.empty() ? o.ground_truth_topic : "";
}

void RosMessageConverter::autoMap(const std::vector<RosTopic>& topics,
                                  const std::map<std::string, std::string>& image_encodings) {
  if (!options_.auto_map) return;
  auto isDepth = [&](const std::string& topic) {
    const auto it = image_encodings.find(topic);
    return it != image_encodings.end() && isRosDepthEncoding(it->second);
  };
  for (Role role : {Role::kImu, Role::kLidar, Role::kCamera, Role::kDepth}) {
    if (!topics_[role].empty()) continue;
    std::set<std::string> candidates;
    for (const RosTopic& t : topics) {
      if (!fits(role, rosTypeInfo(t.type).kind)) continue;
      if (role == Role::kCamera && isDepth(t.topic)) continue;
      if (role == Role::kDepth && !isDepth(t.topic)) continue;
      candidates.insert(t.topic);
    }
    for (const auto& kv : topics_) candidates.erase(kv.second);
    if (candidates.size() == 1) {
      topics_[role] = *candidates.begin();
      report_.note(std::string("--") + roleName(role) + " not given: using the bag's only fitting topic " +
                   topics_[role]);
    } else if (candidates.size() > 1) {
      std::string list;
      for (const std::string& c : candidates) list += " " + c;
      report_.note(std::string("--") + roleName(role) + " not given and several topics fit (" + list.substr(1) +
                   "): none imported; choose one with --" + roleName(role));
    }
  }
  if (topics_[Role::kCameraInfo].empty()) autoMapCameraInfo(topics);
}

/// The camera's CameraInfo: the only CameraInfo topic, else the one in the camera topic's
/// namespace or a parent's (/cam/color/image_raw/compressed -> /cam/color/image_raw/camera_info,
/// /cam/color/camera_info, /cam/camera_info).
void RosMessageConverter::autoMapCameraInfo(const std::vector<RosTopic>& topics) {
  std::set<std::string> candidates;
  for (const RosTopic& t : topics)
    if (rosTypeInfo(t.type).kind == RosMessageKind::kCameraInfo) candidates.insert(t.topic);
  if (candidates.empty()) return;
  std::string chosen;
  if (candidates.size() == 1) {
    chosen = *candidates.begin();
  } else {
    for (std::string ns = topics_[Role::kCamera]; chosen.empty() && !ns.empty();) {
      ns = ns.substr(0, ns.rfind('/'));
      if (candidates.count(ns + "/camera_info")) chosen = ns + "/camera_info";
    }
  }
  if (chosen.empty()) {
    std::string list;
    for (const std::string& c : candidates) list += " " + c;
    report_.note("--camera-info not given and several CameraInfo topics (" + list.substr(1) +
                 ") with none in the camera's namespace: none read; choose one with --camera-info");
    return;
  }
  topics_[Role::kCameraInfo] = chosen;
  report_.note("--camera-info not given: using " + chosen +
               (candidates.size() == 1 ? " (the bag's only CameraInfo topic)" : " (in the camera's namespace)"));
}

std::vector<std::pair<std::string, std::string>> RosMessageConverter::roleTopics() const {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& [role, topic] : topics_)
    if (!topic.empty()) out.emplace_back(roleName(role), topic);
  return out;
}

bool RosMessageConverter::handle(const RosWireMessage& m) {
  const std::string& topic = *m.topic;
  const std::string& type = *m.type;
  const Role role = roleOf(topic);
  if (role == Role::kIgnored) {
    report_.skip("topic not mapped: " + topic + " (" + type + ")", m.where, 1, false);
    return false;
  }
  const RosTypeInfo info = rosTypeInfo(type);
  if (info.kind == RosMessageKind::kUnsupported) {
    report_.skip("unsupported message type " + type + " on " + topic, m.where);
    return false;
  }
  if (m.md5sum && *m.md5sum != info.md5 && *m.md5sum != "*") {
    report_.skip(
        "md5sum " + *m.md5sum + " of " + type + " on " + topic + " differs from the known definition " + info.md5,
        m.where);
    return false;
  }
  if (!fits(role, info.kind)) {
    report_.skip(std::string("topic ") + topic + " is " + type + ", which cannot be the " + roleName(role), m.where);
    return false;
  }
  try {
    if (m.format == RosWireFormat::kCdr) {
      CdrReader r(m.data, m.size, m.where);
      decodeAndConvert(r, info, role, m);
    } else {
      ByteReader r(m.data, m.size, m.where);
      decodeAndConvert(r, info, role, m);
    }
  } catch (const DecodeError& e) {
    // Group by what was wrong (the field and problem), keep the full message as the example.
    std::string what = e.what();
    if (what.rfind(m.where + ": ", 0) == 0) what = what.substr(m.where.size() + 2);
    report_.skip(std::string("undecodable ") + type + " on " + topic + ": " + what, e.what());
    return false;
  }
  return true;
}

namespace {
// The decoders of each wire format, chosen by the reader's type.
RosImu decodeImu(ByteReader& r) { return decodeRosImu(r); }
RosImu decodeImu(CdrReader& r) { return decodeCdrImu(r); }
RosPointCloud2 decodeCloud(ByteReader& r) { return decodeRosPointCloud2(r); }
RosPointCloud2 decodeCloud(CdrReader& r) { return decodeCdrPointCloud2(r); }
RosImage decodeImage(ByteReader& r) { return decodeRosImage(r); }
RosImage decodeImage(CdrReader& r) { return decodeCdrImage(r); }
RosCompressedImage decodeCompressed(ByteReader& r) { return decodeRosCompressedImage(r); }
RosCompressedImage decodeCompressed(CdrReader& r) { return decodeCdrCompressedImage(r); }
RosCameraInfo decodeCameraInfo(ByteReader& r) { return decodeRosCameraInfo(r); }
RosCameraInfo decodeCameraInfo(CdrReader& r) { return decodeCdrCameraInfo(r); }
RosStampedPose decodePose(const RosTypeInfo& info, ByteReader& r) { return info.decode_pose(r); }
RosStampedPose decodePose(const RosTypeInfo& info, CdrReader& r) { return info.decode_pose_cdr(r); }
std::vector<RosStampedPose> decodeTf(ByteReader& r) { return decodeRosTfMessage(r); }
std::vector<RosStampedPose> decodeTf(CdrReader& r) { return decodeCdrTfMessage(r); }
}  // namespace

template <class Reader>
void RosMessageConverter::decodeAndConvert(Reader& r, const RosTypeInfo& info, Role role, const RosWireMessage& m) {
  switch (info.kind) {
    case RosMessageKind::kImu: return imu(decodeImu(r), m);
    case RosMessageKind::kPointCloud2: return cloud(decodeCloud(r), m);
    case RosMessageKind::kImage: {
      const RosImage msg = decodeImage(r);
      return image(role,
                   role == Role::kDepth ? convertRosDepthImage(msg, frameOf(role), m.where)
                                        : convertRosImage(msg, frameOf(role), m.where),
                   m);
    }
    case RosMessageKind::kCompressedImage:
      return image(role, convertRosCompressedImage(decodeCompressed(r), frameOf(role), m.where), m);
    case RosMessageKind::kCameraInfo: return cameraInfo(decodeCameraInfo(r), *m.topic);
    case RosMessageKind::kPose: return pose(decodePose(info, r), m);
    case RosMessageKind::kTfMessage: return transforms(decodeTf(r), m);
    default: return;
  }
}

void RosMessageConverter::finish() {
  for (auto& kv : imu_units_) kv.second->flush();
  if (camera_infos_) report_.metadata("camera_info_messages", std::to_string(camera_infos_));
}

RosMessageConverter::Role RosMessageConverter::roleOf(const std::string& topic) const {
  for (const auto& kv : topics_)
    if (!kv.second.empty() && kv.second == topic) return kv.first;
  return Role::kIgnored;
}

int64_t RosMessageConverter::stampOf(const RosHeader& h, const RosWireMessage& m) {
  if (options_.use_bag_time) return nsToUtime(m.receive_time_ns);
  if (h.sec == 0 && h.nsec == 0) {
    report_.skip("header.stamp is zero: stamped with " + receive_time_ + " instead", m.where, 1, false);
    return nsToUtime(m.receive_time_ns);
  }
  return nsToUtime(h.stampNs());
}

void RosMessageConverter::imu(const RosImu& msg, const RosWireMessage& m) {
  for (double v : msg.angular_velocity)
    if (!std::isfinite(v)) return report_.skip("non-finite angular_velocity", m.where);
  for (double v : msg.linear_acceleration)
    if (!std::isfinite(v)) return report_.skip("non-finite linear_acceleration", m.where);
  const imu_t s = imuFromRos(msg, stampOf(msg.header, m));
  auto& norm = imu_units_[*m.topic];
  if (!norm) {
    const std::string channel = options_.channels.imu;
    norm = std::make_unique<ImuUnitNormaliser>(options_.imu_units, *m.topic, report_,
                                               [this, channel](const imu_t& x) { sink_.observe(channel, x); });
  }
  norm->add(s);
}

void RosMessageConverter::cloud(RosPointCloud2 msg, const RosWireMessage& m) {
  if (options_.use_bag_time) {
    msg.header.sec = static_cast<uint32_t>(m.receive_time_ns / 1000000000LL);
    msg.header.nsec = static_cast<uint32_t>(m.receive_time_ns % 1000000000LL);
  } else if (msg.header.sec == 0 && msg.header.nsec == 0) {
    report_.skip("header.stamp is zero: stamped with " + receive_time_ + " instead", m.where, 1, false);
    msg.header.sec = static_cast<uint32_t>(m.receive_time_ns / 1000000000LL);
    msg.header.nsec = static_cast<uint32_t>(m.receive_time_ns % 1000000000LL);
  }
  PointCloudConversion c = convertPointCloud2(msg, options_.lidar, m.where);
  if (c.non_finite_points) report_.skip("LiDAR points with a NaN/inf coordinate", m.where, c.non_finite_points, false);
  if (c.zero_points) report_.skip("LiDAR points at (0, 0, 0) (no return)", m.where, c.zero_points, false);
  if (report_.metadataValue("lidar_point_layout").empty()) {
    report_.metadataString("lidar_point_layout", c.layout);
    report_.metadataString("lidar_topic", *m.topic);
  }
  sink_.observe(options_.channels.lidar, c.cloud);
}

void RosMessageConverter::image(Role role, image_t img, const RosWireMessage& m) {
  if (options_.use_bag_time) img.utime = nsToUtime(m.receive_time_ns);
  sink_.observe(role == Role::kCameraRight ? options_.channels.camera_right
                : role == Role::kDepth     ? options_.channels.depth
                                           : options_.channels.camera,
                img);
}

/// The first calibrated CameraInfo becomes the report's camera calibration (and metadata
/// camera_info); later ones are only counted, and a change of K or D is noted once.
void RosMessageConverter::cameraInfo(const RosCameraInfo& msg, const std::string& topic) {
  ++camera_infos_;
  if (camera_infos_ == 1) {
    report_.metadata("camera_info", "{topic: " + yamlQuote(topic) + ", width: " + std::to_string(msg.width) +
                                        ", height: " + std::to_string(msg.height) + ", distortion_model: " +
                                        yamlQuote(msg.distortion_model) + ", D: " + yamlList(msg.D) +
                                        ", K: " + yamlList(std::vector<double>(msg.K.begin(), msg.K.end())) + "}");
    first_camera_info_ = msg;
    const std::optional<CameraIntrinsics> k = intrinsicsFromCameraInfo(msg, topic);
    if (!k)
      report_.note("camera_info on " + topic + " is uncalibrated (K[0] = 0): no intrinsics from it");
    else if (!report_.calibration().camera)
      report_.calibration().camera = k;
    return;
  }
  if (!camera_info_changed_ && (msg.K != first_camera_info_.K || msg.D != first_camera_info_.D ||
                                msg.width != first_camera_info_.width || msg.height != first_camera_info_.height)) {
    camera_info_changed_ = true;
    report_.note("camera_info on " + topic + " changes during the bag (message " + std::to_string(camera_infos_) +
                 "): the first is used");
  }
}

void RosMessageConverter::pose(const RosStampedPose& p, const RosWireMessage& m) {
  const pose_t out = poseFromRos(p, stampOf(p.header, m), options_.ground_truth_child_frame);
  if (!p.has_orientation && report_.metadataValue("ground_truth_orientation").empty())
    report_.metadataString("ground_truth_orientation", "none (position only; identity written)");
  sink_.observe(options_.channels.ground_truth, out);
}

/// The transforms to the ground-truth frame (--ground-truth-frame, else the first child frame on
/// the topic) become poses; transforms to other frames are counted.
void RosMessageConverter::transforms(const std::vector<RosStampedPose>& tfs, const RosWireMessage& m) {
  for (const RosStampedPose& t : tfs) {
    if (tf_frame_.empty()) {
      tf_frame_ = options_.ground_truth_tf_frame.empty() ? t.child_frame_id : options_.ground_truth_tf_frame;
      if (options_.ground_truth_tf_frame.empty())
        report_.note("--ground-truth-frame not given: the ground truth is " + *m.topic + "'s transforms to " +
                     tf_frame_ + " (the first child frame on it)");
      report_.metadataString("ground_truth_tf_frame", tf_frame_);
    }
    if (t.child_frame_id == tf_frame_)
      pose(t, m);
    else
      report_.skip("transforms on " + *m.topic + " to another frame than " + tf_frame_ + " (--ground-truth-frame)",
                   m.where, 1, false);
  }
}

}  // namespace livo::import
