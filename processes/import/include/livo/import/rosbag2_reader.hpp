// ROS 2 bags (rosbag2), read natively: a bag directory (metadata.yaml naming the storage, the
// files and the topics), or a single .mcap or .db3 file. Storages: MCAP (mcap_reader.hpp) and
// rosbag2's SQLite 3 (tables topics(id, name, type, serialization_format, ...) and
// messages(id, topic_id, timestamp, data)). Messages come out in each file's order (MCAP: file
// order; SQLite: row id), files in metadata.yaml's order; their payloads are left serialised.
// rosbag2's own compression (metadata.yaml compression_format zstd) is undone: mode FILE (each
// file decompressed to a temporary file, removed after reading) and MESSAGE (each payload).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace livo::import {

class Rosbag2Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Rosbag2Topic {
  std::string topic;
  std::string type;                  // "sensor_msgs/msg/Imu"
  std::string serialization_format;  // "cdr"
  int64_t messages = -1;             // -1: unknown without reading the messages
};

struct Rosbag2Message {
  const Rosbag2Topic* topic = nullptr;
  int64_t receive_time_ns = 0;
  const uint8_t* data = nullptr;
  size_t size = 0;
  std::string where;  // "<file>: message at offset 120 (topic /imu)", "<file>: messages row id 7 (topic /imu)"
  std::string error;  // a message compressed by rosbag2 that does not decompress: why (data is then empty)
};

class Rosbag2Reader {
 public:
  /// A bag directory, or one .mcap / .db3 file. Throws Rosbag2Error for anything else, a
  /// metadata.yaml that cannot be read, an unknown storage or compression.
  explicit Rosbag2Reader(const std::string& input);

  /// "mcap" or "sqlite3".
  const std::string& storage() const { return storage_; }
  const std::vector<std::string>& files() const { return files_; }
  /// Topics from metadata.yaml, else from the files (MCAP summary or a scan; SQLite topics table).
  std::vector<Rosbag2Topic> topics();

  /// Calls `fn` for every message of file `i`; `progress(done, total)` as it goes (bytes or rows).
  /// At damage, throws Rosbag2Error naming the file and offset (or row), after every message
  /// before it was delivered.
  void readFile(size_t i, const std::function<void(const Rosbag2Message&)>& fn,
                const std::function<void(double, double)>& progress = nullptr);
  /// Chunks seen per compression in the MCAP files read so far.
  const std::map<std::string, int64_t>& chunkCompressions() const { return chunk_compressions_; }

 private:
  void readMcap(const std::string& file, const std::function<void(const Rosbag2Message&)>& fn,
                const std::function<void(double, double)>& progress);
  void readSqlite(const std::string& file, const std::function<void(const Rosbag2Message&)>& fn,
                  const std::function<void(double, double)>& progress);
  const Rosbag2Topic& topicFor(const std::string& name, const std::string& type, const std::string& format);

  void deliver(Rosbag2Message& m, const std::function<void(const Rosbag2Message&)>& fn);

  std::string storage_;
  std::string compression_mode_;  // "", "FILE" or "MESSAGE" (zstd)
  std::vector<std::string> files_;
  std::vector<Rosbag2Topic> metadata_topics_;  // from metadata.yaml
  std::map<std::string, Rosbag2Topic> known_;  // topics seen while reading, by name
  std::map<std::string, int64_t> chunk_compressions_;
};

}  // namespace livo::import
