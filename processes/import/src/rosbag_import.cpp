#include "livo/import/rosbag_import.hpp"

#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include "livo/import/bag_reader.hpp"
#include "livo/import/ground_truth_file.hpp"
#include "livo/import/image_encoding.hpp"
#include "livo/import/progress_line.hpp"
#include "livo/import/ros_messages.hpp"
#include "livo/import/stamp_conversion.hpp"
#include "livo/pose_t.hpp"

namespace livo::import {

namespace {

enum class Role { kIgnored, kImu, kLidar, kCamera, kCameraRight, kDepth, kCameraInfo, kGroundTruth };

const char* roleName(Role r) {
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

/// Which roles a message kind can fill.
bool fits(Role role, RosMessageKind kind) {
  switch (role) {
    case Role::kImu: return kind == RosMessageKind::kImu;
    case Role::kLidar: return kind == RosMessageKind::kPointCloud2;
    case Role::kCamera:
    case Role::kCameraRight: return kind == RosMessageKind::kImage || kind == RosMessageKind::kCompressedImage;
    case Role::kDepth: return kind == RosMessageKind::kImage;
    case Role::kCameraInfo: return kind == RosMessageKind::kCameraInfo;
    case Role::kGroundTruth: return kind == RosMessageKind::kPose;
    default: return false;
  }
}

/// The encoding of each sensor_msgs/Image topic's first message (the bag is read until every
/// Image topic has shown one): whether a topic is depth is in its messages, not its type.
std::map<std::string, std::string> firstImageEncodings(const std::string& bag,
                                                       const std::map<uint32_t, BagConnection>& connections) {
  std::set<std::string> image_topics;
  for (const auto& kv : connections)
    if (rosTypeInfo(kv.second.type).kind == RosMessageKind::kImage) image_topics.insert(kv.second.topic);
  std::map<std::string, std::string> encodings;
  if (image_topics.empty()) return encodings;
  struct AllSeen {};
  try {
    BagReader reader(bag);
    reader.readAll([&](const BagMessage& m) {
      const std::string& topic = m.connection->topic;
      if (!image_topics.count(topic) || encodings.count(topic)) return;
      if (rosTypeInfo(m.connection->type).kind != RosMessageKind::kImage) return;
      try {
        ByteReader r(m.data, m.size, bag);
        encodings[topic] = decodeRosImage(r).encoding;
      } catch (const DecodeError&) {
        return;  // the import reports it
      }
      if (encodings.size() == image_topics.size()) throw AllSeen{};
    });
  } catch (const AllSeen&) {
  } catch (const std::exception&) {
    // a damaged bag: what was seen is used; the import reports the damage
  }
  return encodings;
}

class BagConverter {
 public:
  BagConverter(const RosbagImportOptions& o, SortedLogWriter& w, ImportReport& r)
      : options_(o), writer_(w), report_(r) {
    topics_[Role::kImu] = o.imu_topic;
    topics_[Role::kLidar] = o.lidar_topic;
    topics_[Role::kCamera] = o.camera_topic;
    topics_[Role::kCameraRight] = o.camera_right_topic;
    topics_[Role::kDepth] = o.depth_topic;
    topics_[Role::kCameraInfo] = o.camera_info_topic;
    topics_[Role::kGroundTruth] = o.ground_truth_file.empty() ? o.ground_truth_topic : "";
  }

  /// Fills empty roles from the bag's connections when exactly one topic fits. `image_encodings`
  /// (firstImageEncodings) tells depth Image topics, which fit only the depth role, from cameras.
  void autoMap(const std::map<uint32_t, BagConnection>& connections,
               const std::map<std::string, std::string>& image_encodings) {
    if (!options_.auto_map) return;
    auto isDepth = [&](const std::string& topic) {
      const auto it = image_encodings.find(topic);
      return it != image_encodings.end() && isRosDepthEncoding(it->second);
    };
    for (Role role : {Role::kImu, Role::kLidar, Role::kCamera, Role::kDepth}) {
      if (!topics_[role].empty()) continue;
      std::set<std::string> candidates;
      for (const auto& kv : connections) {
        const std::string& topic = kv.second.topic;
        if (!fits(role, rosTypeInfo(kv.second.type).kind)) continue;
        if (role == Role::kCamera && isDepth(topic)) continue;
        if (role == Role::kDepth && !isDepth(topic)) continue;
        candidates.insert(topic);
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
    if (topics_[Role::kCameraInfo].empty()) autoMapCameraInfo(connections);
  }

  /// The camera's CameraInfo: the only CameraInfo topic, else the one in the camera topic's
  /// namespace or a parent's (/cam/color/image_raw/compressed -> /cam/color/image_raw/camera_info,
  /// /cam/color/camera_info, /cam/camera_info).
  void autoMapCameraInfo(const std::map<uint32_t, BagConnection>& connections) {
    std::set<std::string> candidates;
    for (const auto& kv : connections)
      if (rosTypeInfo(kv.second.type).kind == RosMessageKind::kCameraInfo) candidates.insert(kv.second.topic);
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

  void handle(const BagMessage& m, const std::string& bag) {
    const BagConnection& c = *m.connection;
    const Role role = roleOf(c.topic);
    const std::string where = bag + ": message record " + std::to_string(m.record_number) + " (topic " + c.topic + ")";
    if (role == Role::kIgnored) {
      report_.skip("topic not mapped: " + c.topic + " (" + c.type + ")", where, 1, false);
      return;
    }
    const RosTypeInfo info = rosTypeInfo(c.type);
    if (info.kind == RosMessageKind::kUnsupported) {
      report_.skip("unsupported message type " + c.type + " on " + c.topic, where);
      return;
    }
    if (c.md5sum != info.md5 && c.md5sum != "*") {
      report_.skip(
          "md5sum " + c.md5sum + " of " + c.type + " on " + c.topic + " differs from the known definition " + info.md5,
          where);
      return;
    }
    if (!fits(role, info.kind)) {
      report_.skip(std::string("topic ") + c.topic + " is " + c.type + ", which cannot be the " + roleName(role),
                   where);
      return;
    }
    ByteReader r(m.data, m.size, where);
    try {
      switch (info.kind) {
        case RosMessageKind::kImu: return imu(decodeRosImu(r), m, where);
        case RosMessageKind::kPointCloud2: return cloud(decodeRosPointCloud2(r), m, where);
        case RosMessageKind::kImage: {
          const RosImage msg = decodeRosImage(r);
          return image(role,
                       role == Role::kDepth ? convertRosDepthImage(msg, frameOf(role), where)
                                            : convertRosImage(msg, frameOf(role), where),
                       m);
        }
        case RosMessageKind::kCompressedImage:
          return image(role, convertRosCompressedImage(decodeRosCompressedImage(r), frameOf(role), where), m);
        case RosMessageKind::kCameraInfo: return cameraInfo(decodeRosCameraInfo(r), m.connection->topic);
        case RosMessageKind::kPose: return pose(info.decode_pose(r), m, where);
        default: return;
      }
    } catch (const DecodeError& e) {
      // Group by what was wrong (the field and problem), keep the full message as the example.
      std::string what = e.what();
      if (what.rfind(where + ": ", 0) == 0) what = what.substr(where.size() + 2);
      report_.skip(std::string("undecodable ") + c.type + " on " + c.topic + ": " + what, e.what());
    }
  }

  void finish() {
    for (auto& kv : imu_units_) kv.second->flush();
    if (camera_infos_) report_.metadata("camera_info_messages", std::to_string(camera_infos_));
  }

 private:
  Role roleOf(const std::string& topic) const {
    for (const auto& kv : topics_)
      if (!kv.second.empty() && kv.second == topic) return kv.first;
    return Role::kIgnored;
  }
  static std::string frameOf(Role role) { return role == Role::kCameraRight ? "C1" : "C"; }

  int64_t stampOf(const RosHeader& h, const BagMessage& m, const std::string& where) {
    if (options_.use_bag_time) return nsToUtime(m.record_time_ns);
    if (h.sec == 0 && h.nsec == 0) {
      report_.skip("header.stamp is zero: stamped with the bag's receive time instead", where, 1, false);
      return nsToUtime(m.record_time_ns);
    }
    return nsToUtime(h.stampNs());
  }

  void imu(const RosImu& msg, const BagMessage& m, const std::string& where) {
    for (double v : msg.angular_velocity)
      if (!std::isfinite(v)) return report_.skip("non-finite angular_velocity", where);
    for (double v : msg.linear_acceleration)
      if (!std::isfinite(v)) return report_.skip("non-finite linear_acceleration", where);
    imu_t s;
    s.utime = stampOf(msg.header, m, where);
    for (int i = 0; i < 3; ++i) {
      s.angular_velocity[i] = msg.angular_velocity[i];
      s.linear_acceleration[i] = msg.linear_acceleration[i];
    }
    auto& norm = imu_units_[m.connection->topic];
    if (!norm) {
      const std::string channel = options_.channels.imu;
      norm = std::make_unique<ImuUnitNormaliser>(options_.imu_units, m.connection->topic, report_,
                                                 [this, channel](const imu_t& x) { writer_.add(channel, x); });
    }
    norm->add(s);
  }

  void cloud(RosPointCloud2 msg, const BagMessage& m, const std::string& where) {
    if (options_.use_bag_time) {
      msg.header.sec = static_cast<uint32_t>(m.record_time_ns / 1000000000LL);
      msg.header.nsec = static_cast<uint32_t>(m.record_time_ns % 1000000000LL);
    } else if (msg.header.sec == 0 && msg.header.nsec == 0) {
      report_.skip("header.stamp is zero: stamped with the bag's receive time instead", where, 1, false);
      msg.header.sec = static_cast<uint32_t>(m.record_time_ns / 1000000000LL);
      msg.header.nsec = static_cast<uint32_t>(m.record_time_ns % 1000000000LL);
    }
    PointCloudConversion c = convertPointCloud2(msg, options_.lidar, where);
    if (c.non_finite_points) report_.skip("LiDAR points with a NaN/inf coordinate", where, c.non_finite_points, false);
    if (c.zero_points) report_.skip("LiDAR points at (0, 0, 0) (no return)", where, c.zero_points, false);
    if (report_.metadataValue("lidar_point_layout").empty()) {
      report_.metadataString("lidar_point_layout", c.layout);
      report_.metadataString("lidar_topic", m.connection->topic);
    }
    writer_.add(options_.channels.lidar, c.cloud);
  }

  void image(Role role, image_t img, const BagMessage& m) {
    if (options_.use_bag_time) img.utime = nsToUtime(m.record_time_ns);
    writer_.add(role == Role::kCameraRight ? options_.channels.camera_right
                : role == Role::kDepth     ? options_.channels.depth
                                           : options_.channels.camera,
                img);
  }

  /// The first calibrated CameraInfo becomes the report's camera calibration (and metadata
  /// camera_info); later ones are only counted, and a change of K or D is noted once.
  void cameraInfo(const RosCameraInfo& msg, const std::string& topic) {
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

  void pose(const RosStampedPose& p, const BagMessage& m, const std::string& where) {
    pose_t out;
    out.utime = stampOf(p.header, m, where);
    out.parent_frame = "W";
    out.child_frame = options_.ground_truth_child_frame;
    for (int i = 0; i < 3; ++i) out.position[i] = p.position[i];
    out.orientation[0] = p.orientation_xyzw[3];
    out.orientation[1] = p.orientation_xyzw[0];
    out.orientation[2] = p.orientation_xyzw[1];
    out.orientation[3] = p.orientation_xyzw[2];
    if (!p.has_orientation && report_.metadataValue("ground_truth_orientation").empty())
      report_.metadataString("ground_truth_orientation", "none (position only; identity written)");
    writer_.add(options_.channels.ground_truth, out);
  }

  const RosbagImportOptions& options_;
  SortedLogWriter& writer_;
  ImportReport& report_;
  std::map<Role, std::string> topics_;
  std::map<std::string, std::unique_ptr<ImuUnitNormaliser>> imu_units_;
  int64_t camera_infos_ = 0;
  RosCameraInfo first_camera_info_;
  bool camera_info_changed_ = false;

 public:
  const std::map<Role, std::string>& topics() const { return topics_; }
};

/// Connections of a bag: from its index, or from a full pass if it has none.
std::map<uint32_t, BagConnection> bagConnections(const std::string& bag) {
  BagReader reader(bag);
  auto indexed = reader.indexedConnections();
  if (!indexed.empty()) return indexed;
  try {
    reader.readAll([](const BagMessage&) {});
  } catch (const std::exception&) {
  }
  return reader.connections();
}

}  // namespace

void importRosbag(const std::vector<std::string>& bags, const RosbagImportOptions& o, SortedLogWriter& writer,
                  ImportReport& report) {
  BagConverter conv(o, writer, report);
  const bool need_auto = o.auto_map && (o.imu_topic.empty() || o.lidar_topic.empty() || o.camera_topic.empty() ||
                                        o.depth_topic.empty() || o.camera_info_topic.empty());
  if (need_auto && !bags.empty()) {
    try {
      const std::map<uint32_t, BagConnection> connections = bagConnections(bags.front());
      const bool images_to_map = o.camera_topic.empty() || o.depth_topic.empty();
      conv.autoMap(connections, images_to_map ? firstImageEncodings(bags.front(), connections)
                                              : std::map<std::string, std::string>{});
    } catch (const std::exception& e) {
      report.error(e.what());
      return;
    }
  }
  for (const auto& [role, topic] : conv.topics())
    if (!topic.empty()) report.metadataString(std::string("topic_") + roleName(role), topic);
  for (const std::string& bag : bags) {
    try {
      BagReader reader(bag);
      ProgressLine progress("livo-import " + bag, static_cast<double>(reader.fileSize()) / 1e6, "MB", o.progress);
      reader.readAll([&](const BagMessage& m) {
        conv.handle(m, bag);
        progress.update(static_cast<double>(reader.position()) / 1e6);
      });
      progress.finish();
      std::string chunks;
      for (const auto& [c, n] : reader.chunkCompressions())
        chunks += (chunks.empty() ? "" : ", ") + c + ": " + std::to_string(n);
      report.metadata("bag_chunks", "{" + chunks + "}");
    } catch (const std::exception& e) {
      report.error(e.what());
    }
  }
  conv.finish();
  if (!o.ground_truth_file.empty())
    importGroundTruthFile(o.ground_truth_file, o.channels.ground_truth, o.ground_truth_child_frame, writer, report);
}

std::vector<BagTopic> listBagTopics(const std::string& bag) {
  BagReader reader(bag);
  std::map<uint32_t, int64_t> counts;
  std::string error;
  try {
    reader.readAll([&](const BagMessage& m) { ++counts[m.connection->id]; });
  } catch (const std::exception& e) {
    error = e.what();
  }
  std::map<std::string, BagTopic> by_topic;
  for (const auto& [id, c] : reader.connections()) {
    BagTopic& t = by_topic[c.topic];
    t.topic = c.topic;
    t.type = c.type;
    t.messages += counts[id];
  }
  std::vector<BagTopic> out;
  for (auto& kv : by_topic) out.push_back(kv.second);
  if (!error.empty()) throw BagError(error);
  return out;
}

}  // namespace livo::import
