#include "livo/import/rosbag2_import.hpp"

#include "livo/import/ground_truth_file.hpp"
#include "livo/import/progress_line.hpp"
#include "livo/import/ros_message_converter.hpp"
#include "livo/import/rosbag2_reader.hpp"

namespace livo::import {

namespace {

/// CDR, or ROS 1 serialisation (MCAP files converted from ROS 1 bags: message encoding "ros1").
bool readable(const Rosbag2Topic& t) { return t.serialization_format == "cdr" || t.serialization_format == "ros1"; }

RosWireMessage wireMessage(const Rosbag2Message& m) {
  RosWireMessage w;
  w.topic = &m.topic->topic;
  w.type = &m.topic->type;
  w.format = m.topic->serialization_format == "ros1" ? RosWireFormat::kRos1 : RosWireFormat::kCdr;
  w.receive_time_ns = m.receive_time_ns;
  w.data = m.data;
  w.size = m.size;
  w.where = m.where;
  return w;
}

std::vector<RosTopic> rosTopics(const std::vector<Rosbag2Topic>& topics) {
  std::vector<RosTopic> out;
  for (const Rosbag2Topic& t : topics) out.push_back({t.topic, t.type});
  return out;
}

/// The encoding of each Image topic's first message (the first file is read until every Image
/// topic has shown one).
std::map<std::string, std::string> firstImageEncodings(Rosbag2Reader& reader, const std::vector<RosTopic>& topics) {
  FirstImageEncodings first(topics);
  if (first.done() || reader.files().empty()) return first.encodings();
  struct AllSeen {};
  try {
    reader.readFile(0, [&](const Rosbag2Message& m) {
      if (readable(*m.topic) && m.error.empty()) first.offer(wireMessage(m));
      if (first.done()) throw AllSeen{};
    });
  } catch (const AllSeen&) {
  } catch (const std::exception&) {
    // a damaged bag: what was seen is used; the import reports the damage
  }
  return first.encodings();
}

}  // namespace

void importRosbag2(const std::string& input, const RosbagImportOptions& o, SortedLogWriter& writer,
                   ImportReport& report) {
  LogWriterSink sink(writer);
  RosMessageConverter conv(o, sink, report);
  std::unique_ptr<Rosbag2Reader> reader;
  try {
    reader = std::make_unique<Rosbag2Reader>(input);
    const bool need_auto = o.auto_map && (o.imu_topic.empty() || o.lidar_topic.empty() || o.camera_topic.empty() ||
                                          o.depth_topic.empty() || o.camera_info_topic.empty());
    if (need_auto) {
      const std::vector<RosTopic> topics = rosTopics(reader->topics());
      const bool images_to_map = o.camera_topic.empty() || o.depth_topic.empty();
      conv.autoMap(topics, images_to_map ? firstImageEncodings(*reader, topics) : std::map<std::string, std::string>{});
    }
  } catch (const std::exception& e) {
    report.error(e.what());
    return;
  }
  for (const auto& [role, topic] : conv.roleTopics()) report.metadataString("topic_" + role, topic);
  report.metadataString("bag_storage", reader->storage());
  for (size_t i = 0; i < reader->files().size(); ++i) {
    const std::string& file = reader->files()[i];
    ProgressLine progress("livo-import " + file, 100.0, "%", o.progress);
    try {
      reader->readFile(
          i,
          [&](const Rosbag2Message& m) {
            if (!m.error.empty()) {
              report.skip("message on " + m.topic->topic + " does not decompress: " + m.error, m.where);
              return;
            }
            if (!readable(*m.topic)) {
              report.skip("serialization format '" + m.topic->serialization_format + "' of " + m.topic->topic +
                              " is neither cdr nor ros1",
                          m.where);
              return;
            }
            conv.handle(wireMessage(m));
          },
          [&](double done, double total) { progress.update(total > 0 ? 100.0 * done / total : 0.0); });
    } catch (const std::exception& e) {
      report.error(e.what());
    }
    progress.finish();
  }
  if (!reader->chunkCompressions().empty()) {
    std::string chunks;
    for (const auto& [c, n] : reader->chunkCompressions())
      chunks += (chunks.empty() ? "" : ", ") + c + ": " + std::to_string(n);
    report.metadata("bag_chunks", "{" + chunks + "}");
  }
  conv.finish();
  if (!o.ground_truth_file.empty())
    importGroundTruthFile(o.ground_truth_file, o.channels.ground_truth, o.ground_truth_child_frame, writer, report);
}

std::vector<BagTopic> listRosbag2Topics(const std::string& input) {
  Rosbag2Reader reader(input);
  std::vector<BagTopic> out;
  for (const Rosbag2Topic& t : reader.topics()) out.push_back({t.topic, t.type, t.messages});
  return out;
}

}  // namespace livo::import
