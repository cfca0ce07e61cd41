// MCAP files (https://mcap.dev/spec), read natively: a linear scan of the data section in file
// order (Header, Schema, Channel, Message and Chunk records; chunks uncompressed, zstd or lz4),
// which works for files without a summary and for files cut off mid-write; and the summary
// section (Schema, Channel and Statistics records, found from the Footer) for a bag's channels and
// message counts without reading its messages. Index records are not needed for a full read and
// are skipped; CRCs are not checked (a damaged record shows as a decoding error of its message).
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace livo::import {

class McapError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct McapChannel {
  uint16_t id = 0;
  std::string topic;
  std::string message_encoding;  // "cdr" for ROS 2
  std::string schema_name;       // "sensor_msgs/msg/Imu" ("" without a schema)
  std::string schema_encoding;   // "ros2msg", "ros2idl", ...
};

struct McapMessage {
  const McapChannel* channel = nullptr;
  uint32_t sequence = 0;
  uint64_t log_time_ns = 0;  // the recorder's receive time
  uint64_t publish_time_ns = 0;
  const uint8_t* data = nullptr;
  size_t size = 0;
  int64_t number = 0;         // 1-based count of message records in the file
  std::string where;          // "<file>: message at offset 120" / "...: chunk at offset 80, record at byte 312"
};

/// What the summary section tells (empty `channels` if the file has none).
struct McapSummary {
  std::map<uint16_t, McapChannel> channels;
  std::map<uint16_t, uint64_t> message_counts;  // per channel, from the Statistics record
  bool has_statistics = false;
};

class McapReader {
 public:
  /// Opens and checks the leading magic; throws McapError naming the file otherwise.
  explicit McapReader(std::string path);
  ~McapReader();
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;

  /// The summary section, found from the Footer at the end of the file (no message is read).
  McapSummary readSummary();

  /// Calls `fn` for every message in file order. At a truncated or corrupt record it throws
  /// McapError naming the file, the record's offset and what is wrong, after every message before
  /// it was delivered (including the readable part of a damaged chunk).
  void readAll(const std::function<void(const McapMessage&)>& fn);

  const std::map<uint16_t, McapChannel>& channels() const { return channels_; }
  uint64_t fileSize() const { return file_size_; }
  uint64_t position() const { return position_; }
  /// Chunks seen per compression ("none", "zstd", "lz4").
  const std::map<std::string, int64_t>& chunkCompressions() const { return chunk_compressions_; }

 private:
  struct Schema {
    std::string name, encoding;
  };
  void parseRecords(const uint8_t* data, size_t size, const std::string& where_prefix, bool in_chunk,
                    const std::function<void(const McapMessage&)>* fn);
  void parseChunk(const uint8_t* data, size_t size, const std::string& where,
                  const std::function<void(const McapMessage&)>& fn);
  void addSchema(const uint8_t* data, size_t size, const std::string& where);
  void addChannel(const uint8_t* data, size_t size, const std::string& where);
  void deliver(const uint8_t* data, size_t size, const std::string& where,
               const std::function<void(const McapMessage&)>& fn);

  std::string path_;
  std::FILE* file_ = nullptr;
  uint64_t file_size_ = 0;
  uint64_t position_ = 0;
  int64_t messages_ = 0;
  std::map<uint16_t, Schema> schemas_;
  std::map<uint16_t, McapChannel> channels_;
  std::map<std::string, int64_t> chunk_compressions_;
};

}  // namespace livo::import
