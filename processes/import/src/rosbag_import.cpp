#include "livo/import/rosbag_import.hpp"

#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include "livo/import/bag_reader.hpp"
#include "livo/import/ground_truth_file.hpp"
#include "livo/import/progress_line.hpp"
#include "livo/import/ros_message_converter.hpp"

namespace livo::import {

namespace {

std::vector<RosTopic> topicsOf(const std::map<uint32_t, BagConnection>& connections) {
  std::vector<RosTopic> topics;
  for (const auto& kv : connections) topics.push_back({kv.second.topic, kv.second.type});
  return topics;
}

RosWireMessage wireMessage(const BagMessage& m, const std::string& bag) {
  RosWireMessage w;
  w.topic = &m.connection->topic;
  w.type = &m.connection->type;
  w.md5sum = &m.connection->md5sum;
  w.format = RosWireFormat::kRos1;
  w.receive_time_ns = m.record_time_ns;
  w.data = m.data;
  w.size = m.size;
  w.where = bag + ": message record " + std::to_string(m.record_number) + " (topic " + m.connection->topic + ")";
  return w;
}

/// The encoding of each sensor_msgs/Image topic's first message (the bag is read until every
/// Image topic has shown one).
std::map<std::string, std::string> firstImageEncodings(const std::string& bag,
                                                       const std::map<uint32_t, BagConnection>& connections) {
  FirstImageEncodings first(topicsOf(connections));
  if (first.done()) return first.encodings();
  struct AllSeen {};
  try {
    BagReader reader(bag);
    reader.readAll([&](const BagMessage& m) {
      first.offer(wireMessage(m, bag));
      if (first.done()) throw AllSeen{};
    });
  } catch (const AllSeen&) {
  } catch (const std::exception&) {
    // a damaged bag: what was seen is used; the import reports the damage
  }
  return first.encodings();
}

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
  LogWriterSink sink(writer);
  RosMessageConverter conv(o, sink, report);
  const bool need_auto = o.auto_map && (o.imu_topic.empty() || o.lidar_topic.empty() || o.camera_topic.empty() ||
                                        o.depth_topic.empty() || o.camera_info_topic.empty());
  if (need_auto && !bags.empty()) {
    try {
      const std::map<uint32_t, BagConnection> connections = bagConnections(bags.front());
      const bool images_to_map = o.camera_topic.empty() || o.depth_topic.empty();
      conv.autoMap(topicsOf(connections), images_to_map ? firstImageEncodings(bags.front(), connections)
                                                        : std::map<std::string, std::string>{});
    } catch (const std::exception& e) {
      report.error(e.what());
      return;
    }
  }
  for (const auto& [role, topic] : conv.roleTopics()) report.metadataString("topic_" + role, topic);
  for (const std::string& bag : bags) {
    try {
      BagReader reader(bag);
      ProgressLine progress("livo-import " + bag, static_cast<double>(reader.fileSize()) / 1e6, "MB", o.progress);
      reader.readAll([&](const BagMessage& m) {
        conv.handle(wireMessage(m, bag));
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
