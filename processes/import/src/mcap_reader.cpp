#include "livo/import/mcap_reader.hpp"

#include <cstring>

#include "livo/import/byte_reader.hpp"
#include "livo/import/chunk_decompression.hpp"

namespace livo::import {

namespace {

constexpr uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr uint8_t kOpFooter = 0x02;
constexpr uint8_t kOpSchema = 0x03;
constexpr uint8_t kOpChannel = 0x04;
constexpr uint8_t kOpMessage = 0x05;
constexpr uint8_t kOpChunk = 0x06;
constexpr uint8_t kOpStatistics = 0x0B;
constexpr uint8_t kOpDataEnd = 0x0F;
constexpr uint64_t kFooterRecordBytes = 1 + 8 + 20;
constexpr uint64_t kMaxRecordBytes = 1ull << 36;  // sanity bound against corrupt lengths

std::string offsetText(uint64_t off) { return "offset " + std::to_string(off); }

/// MCAP string: uint32 length, then the bytes (as a ROS 1 string).
std::string mcapString(ByteReader& r, const char* field) { return r.string(field); }

/// The Statistics record's channel message counts.
void readStatistics(const uint8_t* data, size_t size, const std::string& where, McapSummary& s) {
  ByteReader r(data, size, where + " (Statistics record)");
  r.u64("message_count");
  r.u16("schema_count");
  r.u32("channel_count");
  r.u32("attachment_count");
  r.u32("metadata_count");
  r.u32("chunk_count");
  r.u64("message_start_time");
  r.u64("message_end_time");
  const uint32_t bytes = r.u32("channel_message_counts");
  ByteReader m(r.bytes(bytes, "channel_message_counts"), bytes, r.context());
  while (m.remaining() > 0) {
    const uint16_t id = m.u16("channel_message_counts[].channel_id");
    s.message_counts[id] = m.u64("channel_message_counts[].count");
  }
  s.has_statistics = true;
}

}  // namespace

McapReader::McapReader(std::string path) : path_(std::move(path)) {
  file_ = std::fopen(path_.c_str(), "rb");
  if (!file_) throw McapError(path_ + ": cannot open");
  std::fseek(file_, 0, SEEK_END);
  file_size_ = static_cast<uint64_t>(std::ftell(file_));
  std::fseek(file_, 0, SEEK_SET);
  uint8_t magic[8] = {};
  if (std::fread(magic, 1, 8, file_) != 8 || std::memcmp(magic, kMagic, 8) != 0) {
    std::fclose(file_);
    file_ = nullptr;
    throw McapError(path_ + ": not an MCAP file (no MCAP0 magic)");
  }
  position_ = 8;
}

McapReader::~McapReader() {
  if (file_) std::fclose(file_);
}

void McapReader::addSchema(const uint8_t* data, size_t size, const std::string& where) {
  ByteReader r(data, size, where + " (Schema record)");
  const uint16_t id = r.u16("id");
  Schema s;
  s.name = mcapString(r, "name");
  s.encoding = mcapString(r, "encoding");
  schemas_[id] = s;
}

void McapReader::addChannel(const uint8_t* data, size_t size, const std::string& where) {
  ByteReader r(data, size, where + " (Channel record)");
  McapChannel c;
  c.id = r.u16("id");
  const uint16_t schema_id = r.u16("schema_id");
  c.topic = mcapString(r, "topic");
  c.message_encoding = mcapString(r, "message_encoding");
  if (schema_id != 0) {
    const auto it = schemas_.find(schema_id);
    if (it == schemas_.end())
      throw McapError(where + ": channel " + std::to_string(c.id) + " (topic " + c.topic + ") refers to schema " +
                      std::to_string(schema_id) + ", which no Schema record before it defines");
    c.schema_name = it->second.name;
    c.schema_encoding = it->second.encoding;
  }
  if (!channels_.count(c.id)) channels_.emplace(c.id, std::move(c));
}

void McapReader::deliver(const uint8_t* data, size_t size, const std::string& where,
                         const std::function<void(const McapMessage&)>& fn) {
  ByteReader r(data, size, where + " (Message record)");
  McapMessage m;
  const uint16_t channel = r.u16("channel_id");
  m.sequence = r.u32("sequence");
  m.log_time_ns = r.u64("log_time");
  m.publish_time_ns = r.u64("publish_time");
  m.size = r.remaining();
  m.data = r.bytes(m.size, "data");
  ++messages_;
  const auto it = channels_.find(channel);
  if (it == channels_.end())
    throw McapError(where + ": message " + std::to_string(messages_) + " refers to channel " +
                    std::to_string(channel) + ", which no Channel record before it defines");
  m.channel = &it->second;
  m.number = messages_;
  m.where = where + " (topic " + it->second.topic + ")";
  fn(m);
}

/// The records of a chunk (or of the summary, `fn` nullptr): Schema and Channel are kept,
/// Messages delivered, others skipped.
void McapReader::parseRecords(const uint8_t* data, size_t size, const std::string& where_prefix, bool in_chunk,
                              const std::function<void(const McapMessage&)>* fn) {
  ByteReader in(data, size, where_prefix);
  while (in.remaining() > 0) {
    const std::string where = where_prefix + (in_chunk ? ", record at byte " : ", record at ") +
                              std::to_string(in.position());
    const uint8_t op = in.u8("opcode");
    const uint64_t len = in.u64("record length");
    if (len > in.remaining())
      throw McapError(where + ": record of " + std::to_string(len) + " bytes, " + std::to_string(in.remaining()) +
                      " left (truncated or corrupt)");
    const uint8_t* body = in.bytes(len, "record");
    if (op == kOpSchema) addSchema(body, len, where);
    if (op == kOpChannel) addChannel(body, len, where);
    if (op == kOpMessage && fn) deliver(body, len, where, *fn);
  }
}

McapSummary McapReader::readSummary() {
  McapSummary s;
  if (file_size_ < 8 + kFooterRecordBytes + 8) return s;
  const uint64_t footer_pos = file_size_ - 8 - kFooterRecordBytes;
  uint8_t footer[kFooterRecordBytes + 8];
  std::fseek(file_, static_cast<long>(footer_pos), SEEK_SET);
  const bool read = std::fread(footer, 1, sizeof footer, file_) == sizeof footer;
  std::fseek(file_, static_cast<long>(position_), SEEK_SET);
  if (!read || footer[0] != kOpFooter || std::memcmp(footer + kFooterRecordBytes, kMagic, 8) != 0) return s;
  ByteReader f(footer + 1, kFooterRecordBytes - 1, path_ + ": footer");
  if (f.u64("length") != 20) return s;
  const uint64_t summary_start = f.u64("summary_start");
  if (summary_start == 0 || summary_start >= footer_pos) return s;
  std::vector<uint8_t> summary(footer_pos - summary_start);
  std::fseek(file_, static_cast<long>(summary_start), SEEK_SET);
  const bool got = std::fread(summary.data(), 1, summary.size(), file_) == summary.size();
  std::fseek(file_, static_cast<long>(position_), SEEK_SET);
  if (!got) return s;
  const auto saved_schemas = schemas_;
  const auto saved_channels = channels_;
  try {
    const std::string where = path_ + ": summary at " + offsetText(summary_start);
    ByteReader in(summary.data(), summary.size(), where);
    while (in.remaining() > 0) {
      const std::string rec_where = where + ", record at byte " + std::to_string(in.position());
      const uint8_t op = in.u8("opcode");
      const uint64_t len = in.u64("record length");
      const uint8_t* body = in.bytes(len, "record");
      if (op == kOpSchema) addSchema(body, len, rec_where);
      if (op == kOpChannel) addChannel(body, len, rec_where);
      if (op == kOpStatistics) readStatistics(body, len, rec_where, s);
    }
    s.channels = channels_;
  } catch (const std::exception&) {
    s = McapSummary{};  // a damaged summary: the caller scans the file instead
  }
  schemas_ = saved_schemas;
  channels_ = saved_channels;
  return s;
}

void McapReader::parseChunk(const uint8_t* data, size_t size, const std::string& where,
                            const std::function<void(const McapMessage&)>& fn) {
  ByteReader r(data, size, where + " (Chunk record)");
  r.u64("message_start_time");
  r.u64("message_end_time");
  const uint64_t uncompressed_size = r.u64("uncompressed_size");
  r.u32("uncompressed_crc");
  std::string compression = mcapString(r, "compression");
  const uint64_t records_size = r.u64("records");
  const uint8_t* records = r.bytes(records_size, "records");
  if (compression.empty()) compression = "none";
  ++chunk_compressions_[compression];
  if (uncompressed_size > kMaxRecordBytes)
    throw McapError(where + ": chunk claims " + std::to_string(uncompressed_size) + " uncompressed bytes (corrupt?)");
  DecompressedChunk chunk;
  if (compression == "zstd")
    chunk = decompressZstd(records, records_size, uncompressed_size);
  else if (compression == "none" || compression == "lz4")
    chunk = decompressChunk(compression, records, records_size, uncompressed_size);
  else
    throw McapError(where + ": chunk compression '" + compression + "' is not supported (none, zstd, lz4)");
  if (!chunk.error.empty() && chunk.data.empty()) throw McapError(where + ": chunk: " + chunk.error);
  try {
    parseRecords(chunk.data.data(), chunk.data.size(), where, true, &fn);
  } catch (const DecodeError& e) {
    if (chunk.complete) throw McapError(e.what());
    // A damaged chunk ends with a cut record: the decompression error says why.
  } catch (const McapError&) {
    if (chunk.complete) throw;
  }
  if (!chunk.complete) throw McapError(where + ": chunk: " + chunk.error + "; messages before the damage were kept");
}

void McapReader::readAll(const std::function<void(const McapMessage&)>& fn) {
  std::vector<uint8_t> body;
  while (true) {
    const uint64_t offset = position_;
    const std::string where = path_ + ": record at " + offsetText(offset);
    uint8_t head[9];
    const size_t got = std::fread(head, 1, 9, file_);
    if (got == 0) throw McapError(path_ + ": ends at " + offsetText(offset) + " without a Footer (truncated)");
    if (got != 9) throw McapError(where + ": file ends inside the record's opcode and length (truncated)");
    const uint8_t op = head[0];
    uint64_t len = 0;
    std::memcpy(&len, head + 1, 8);
    const uint64_t available = file_size_ - offset - 9;
    const bool truncated = len > available;
    if (truncated && (op == kOpMessage || op == kOpChunk || len > kMaxRecordBytes))
      throw McapError(where + ": record (opcode " + std::to_string(op) + ") needs " + std::to_string(len) +
                      " bytes, the file ends after " + std::to_string(available) + " (truncated)");
    if (truncated) throw McapError(where + ": record (opcode " + std::to_string(op) + ") is cut off (truncated)");
    body.resize(len);
    if (std::fread(body.data(), 1, len, file_) != len) throw McapError(where + ": read error in record data");
    position_ = offset + 9 + len;
    const std::string rec_where = path_ + ": " + (op == kOpChunk ? "chunk at " : "message at ") + offsetText(offset);
    try {
      if (op == kOpFooter || op == kOpDataEnd) return;  // the summary follows: no message there
      if (op == kOpSchema) addSchema(body.data(), len, where);
      if (op == kOpChannel) addChannel(body.data(), len, where);
      if (op == kOpMessage) deliver(body.data(), len, rec_where, fn);
      if (op == kOpChunk) parseChunk(body.data(), len, rec_where, fn);
    } catch (const DecodeError& e) {
      throw McapError(e.what());
    }
  }
}

}  // namespace livo::import
