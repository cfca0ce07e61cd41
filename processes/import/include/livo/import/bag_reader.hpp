// ROS 1 bag files (format 2.0), read natively: the bag header, chunk records (none / bz2 / lz4),
// connection records (topic, type, md5sum, message definition) and message data records, in file
// order. Index and chunk-info records are not needed for a full sequential read and are skipped,
// so bags whose recording was cut off (no index) read too.
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>

namespace livo::import {

class BagError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct BagConnection {
  uint32_t id = 0;
  std::string topic;
  std::string type;  // e.g. "sensor_msgs/Imu"
  std::string md5sum;
  std::string message_definition;
  std::string callerid;
};

struct BagMessage {
  const BagConnection* connection = nullptr;
  int64_t record_time_ns = 0;     // the bag's receive time of the message
  const uint8_t* data = nullptr;  // serialised ROS message
  size_t size = 0;
  int64_t record_number = 0;  // 1-based count of message records in the file
  uint64_t chunk_offset = 0;  // file offset of the chunk (or record) holding the message
};

class BagReader {
 public:
  /// Opens and checks the "#ROSBAG V2.0" magic; throws BagError naming the file otherwise.
  explicit BagReader(std::string path);
  ~BagReader();
  BagReader(const BagReader&) = delete;
  BagReader& operator=(const BagReader&) = delete;

  /// Calls `fn` for every message in file order. At a truncated or corrupt record it throws
  /// BagError naming the file, the record's offset and the field, after every message before
  /// it was delivered (including the readable part of a damaged chunk).
  void readAll(const std::function<void(const BagMessage&)>& fn);

  /// Connections from the index section at the end of the bag (no chunk is read). Empty if the
  /// bag has no index (recording cut off). Does not change where readAll() starts.
  std::map<uint32_t, BagConnection> indexedConnections();

  const std::map<uint32_t, BagConnection>& connections() const { return connections_; }
  uint64_t fileSize() const { return file_size_; }
  /// Bytes read so far (for progress).
  uint64_t position() const { return position_; }
  /// Chunks seen per compression ("none", "bz2", "lz4").
  const std::map<std::string, int64_t>& chunkCompressions() const { return chunk_compressions_; }

 private:
  struct Record {
    std::map<std::string, std::string> header;
    const uint8_t* data = nullptr;
    size_t size = 0;
  };
  void parseChunk(const uint8_t* data, size_t size, uint64_t chunk_offset,
                  const std::function<void(const BagMessage&)>& fn);
  void addConnection(const Record& r, const std::string& where);
  void deliver(const Record& r, uint64_t offset, const std::string& where,
               const std::function<void(const BagMessage&)>& fn);

  std::string path_;
  std::FILE* file_ = nullptr;
  uint64_t file_size_ = 0;
  uint64_t position_ = 0;
  int64_t messages_ = 0;
  std::map<uint32_t, BagConnection> connections_;
  std::map<std::string, int64_t> chunk_compressions_;
};

}  // namespace livo::import
