#include "livo/import/bag_reader.hpp"

#include <cstring>
#include <vector>

#include "livo/import/byte_reader.hpp"
#include "livo/import/chunk_decompression.hpp"

namespace livo::import {

namespace {

constexpr uint8_t kOpMessageData = 0x02;
constexpr uint8_t kOpBagHeader = 0x03;
constexpr uint8_t kOpIndexData = 0x04;
constexpr uint8_t kOpChunk = 0x05;
constexpr uint8_t kOpChunkInfo = 0x06;
constexpr uint8_t kOpConnection = 0x07;
constexpr uint32_t kMaxHeaderBytes = 64u << 20;  // sanity bound against corrupt lengths

/// "name=value" fields, each prefixed by its uint32 length.
std::map<std::string, std::string> parseHeader(const uint8_t* p, size_t n, const std::string& where) {
  std::map<std::string, std::string> fields;
  ByteReader r(p, n, where);
  while (r.remaining() > 0) {
    const uint32_t len = r.u32("header field length");
    const uint8_t* f = r.bytes(len, "header field");
    const void* eq = std::memchr(f, '=', len);
    if (!eq) r.fail("header field", "no '=' in a header field");
    const size_t k = static_cast<const uint8_t*>(eq) - f;
    fields[std::string(reinterpret_cast<const char*>(f), k)] =
        std::string(reinterpret_cast<const char*>(f) + k + 1, len - k - 1);
  }
  return fields;
}

const std::string& field(const std::map<std::string, std::string>& h, const std::string& name,
                         const std::string& where) {
  auto it = h.find(name);
  if (it == h.end()) throw BagError(where + ": missing header field '" + name + "'");
  return it->second;
}

template <class T>
T fieldAs(const std::map<std::string, std::string>& h, const std::string& name, const std::string& where) {
  const std::string& v = field(h, name, where);
  if (v.size() != sizeof(T))
    throw BagError(where + ": header field '" + name + "' has " + std::to_string(v.size()) + " bytes, expected " +
                   std::to_string(sizeof(T)));
  T out;
  std::memcpy(&out, v.data(), sizeof(T));
  return out;
}

uint8_t opOf(const std::map<std::string, std::string>& h, const std::string& where) {
  return fieldAs<uint8_t>(h, "op", where);
}

std::string hexOffset(uint64_t off) { return "offset " + std::to_string(off); }

}  // namespace

BagReader::BagReader(std::string path) : path_(std::move(path)) {
  file_ = std::fopen(path_.c_str(), "rb");
  if (!file_) throw BagError(path_ + ": cannot open");
  std::fseek(file_, 0, SEEK_END);
  file_size_ = static_cast<uint64_t>(std::ftell(file_));
  std::fseek(file_, 0, SEEK_SET);
  char magic[13] = {};
  if (std::fread(magic, 1, 13, file_) != 13 || std::memcmp(magic, "#ROSBAG V", 9) != 0) {
    std::fclose(file_);
    file_ = nullptr;
    throw BagError(path_ + ": not a ROS bag (no '#ROSBAG V' magic)");
  }
  if (std::memcmp(magic, "#ROSBAG V2.0\n", 13) != 0) {
    std::fclose(file_);
    file_ = nullptr;
    throw BagError(path_ + ": bag format " + std::string(magic + 8, 4) + " is not supported (only V2.0)");
  }
  position_ = 13;
}

BagReader::~BagReader() {
  if (file_) std::fclose(file_);
}

void BagReader::addConnection(const Record& r, const std::string& where) {
  BagConnection c;
  c.id = fieldAs<uint32_t>(r.header, "conn", where);
  c.topic = field(r.header, "topic", where);
  const auto inner = parseHeader(r.data, r.size, where + " (connection header)");
  const std::string inner_where = where + " (connection " + std::to_string(c.id) + ", topic " + c.topic + ")";
  c.type = field(inner, "type", inner_where);
  c.md5sum = field(inner, "md5sum", inner_where);
  auto def = inner.find("message_definition");
  if (def != inner.end()) c.message_definition = def->second;
  auto caller = inner.find("callerid");
  if (caller != inner.end()) c.callerid = caller->second;
  connections_.emplace(c.id, std::move(c));
}

void BagReader::deliver(const Record& r, uint64_t offset, const std::string& where,
                        const std::function<void(const BagMessage&)>& fn) {
  const uint32_t conn = fieldAs<uint32_t>(r.header, "conn", where);
  const uint64_t t = fieldAs<uint64_t>(r.header, "time", where);
  auto it = connections_.find(conn);
  ++messages_;
  if (it == connections_.end())
    throw BagError(where + ": message record " + std::to_string(messages_) + " refers to unknown connection " +
                   std::to_string(conn));
  BagMessage m;
  m.connection = &it->second;
  m.record_time_ns = static_cast<int64_t>(t & 0xffffffffu) * 1000000000LL + static_cast<int64_t>(t >> 32);
  m.data = r.data;
  m.size = r.size;
  m.record_number = messages_;
  m.chunk_offset = offset;
  fn(m);
}

void BagReader::parseChunk(const uint8_t* data, size_t size, uint64_t chunk_offset,
                           const std::function<void(const BagMessage&)>& fn) {
  const std::string chunk_where = path_ + ": chunk at " + hexOffset(chunk_offset);
  ByteReader in(data, size, chunk_where);
  while (in.remaining() > 0) {
    const size_t rec_pos = in.position();
    const std::string where = chunk_where + ", inner record at byte " + std::to_string(rec_pos);
    Record r;
    const uint32_t hlen = in.u32("record header length");
    r.header = parseHeader(in.bytes(hlen, "record header"), hlen, where);
    const uint32_t dlen = in.u32("record data length");
    r.data = in.bytes(dlen, "record data");
    r.size = dlen;
    const uint8_t op = opOf(r.header, where);
    if (op == kOpConnection) {
      if (!connections_.count(fieldAs<uint32_t>(r.header, "conn", where))) addConnection(r, where);
    } else if (op == kOpMessageData) {
      deliver(r, chunk_offset, where, fn);
    } else {
      throw BagError(where + ": unexpected record op " + std::to_string(op) + " inside a chunk");
    }
  }
}

std::map<uint32_t, BagConnection> BagReader::indexedConnections() {
  std::map<uint32_t, BagConnection> found;
  auto readRecord = [&](uint64_t offset, Record& r, std::vector<uint8_t>& header, std::vector<uint8_t>& data) {
    std::fseek(file_, static_cast<long>(offset), SEEK_SET);
    uint32_t hlen = 0, dlen = 0;
    if (std::fread(&hlen, 1, 4, file_) != 4 || hlen > kMaxHeaderBytes || hlen > file_size_ - offset) return false;
    header.resize(hlen);
    if (std::fread(header.data(), 1, hlen, file_) != hlen) return false;
    if (std::fread(&dlen, 1, 4, file_) != 4 || dlen > file_size_ - offset - 8 - hlen) return false;
    data.resize(dlen);
    if (std::fread(data.data(), 1, dlen, file_) != dlen) return false;
    r.header = parseHeader(header.data(), hlen, path_ + ": record at " + hexOffset(offset));
    r.data = data.data();
    r.size = dlen;
    return true;
  };
  std::vector<uint8_t> header, data;
  Record bag_header;
  const auto saved = connections_;
  try {
    if (readRecord(13, bag_header, header, data) && opOf(bag_header.header, path_) == kOpBagHeader) {
      const uint64_t index_pos = fieldAs<uint64_t>(bag_header.header, "index_pos", path_ + ": bag header");
      uint64_t offset = index_pos;
      Record r;
      while (index_pos > 13 && offset < file_size_ && readRecord(offset, r, header, data)) {
        if (opOf(r.header, path_) == kOpConnection) addConnection(r, path_ + ": index connection record");
        offset += 8 + header.size() + data.size();
      }
    }
  } catch (const std::exception&) {
  }
  found = connections_;
  connections_ = saved;
  std::fseek(file_, static_cast<long>(position_), SEEK_SET);
  return found;
}

void BagReader::readAll(const std::function<void(const BagMessage&)>& fn) {
  std::vector<uint8_t> header, data;
  while (true) {
    const uint64_t offset = position_;
    const std::string where = path_ + ": record at " + hexOffset(offset);
    uint32_t hlen = 0;
    const size_t got = std::fread(&hlen, 1, 4, file_);
    if (got == 0) return;  // clean end of file
    if (got != 4) throw BagError(where + ": file ends inside the record header length (truncated)");
    if (hlen > kMaxHeaderBytes || hlen > file_size_ - offset)
      throw BagError(where + ": header length " + std::to_string(hlen) + " exceeds the file (truncated or corrupt)");
    header.resize(hlen);
    if (std::fread(header.data(), 1, hlen, file_) != hlen)
      throw BagError(where + ": file ends inside the record header (truncated)");
    Record r;
    r.header = parseHeader(header.data(), hlen, where);
    uint32_t dlen = 0;
    if (std::fread(&dlen, 1, 4, file_) != 4) throw BagError(where + ": file ends before the data length (truncated)");
    const uint8_t op = opOf(r.header, where);
    const uint64_t data_start = offset + 8 + hlen;
    const uint64_t available = file_size_ > data_start ? file_size_ - data_start : 0;
    const bool truncated = dlen > available;
    data.resize(truncated ? available : dlen);
    if (std::fread(data.data(), 1, data.size(), file_) != data.size())
      throw BagError(where + ": read error in record data");
    position_ = data_start + data.size();
    r.data = data.data();
    r.size = data.size();

    if (op == kOpBagHeader) {
      if (r.header.count("encryptor"))
        throw BagError(where + ": encrypted bags are not supported (encryptor " + r.header.at("encryptor") + ")");
    } else if (op == kOpChunk) {
      const std::string& compression = field(r.header, "compression", where);
      const uint32_t usize = fieldAs<uint32_t>(r.header, "size", where);
      ++chunk_compressions_[compression];
      DecompressedChunk chunk = decompressChunk(compression, r.data, r.size, usize);
      if (!chunk.error.empty() && chunk.data.empty()) throw BagError(where + ": chunk: " + chunk.error);
      try {
        parseChunk(chunk.data.data(), chunk.data.size(), offset, fn);
      } catch (const DecodeError& e) {
        if (chunk.complete) throw BagError(e.what());
        // A damaged chunk ends with a cut record: the decompression error says why.
      }
      if (!chunk.complete) throw BagError(where + ": chunk: " + chunk.error + "; messages before the damage were kept");
    } else if (op == kOpConnection) {
      if (!connections_.count(fieldAs<uint32_t>(r.header, "conn", where))) addConnection(r, where);
    } else if (op == kOpMessageData) {
      deliver(r, offset, where, fn);
    } else if (op != kOpIndexData && op != kOpChunkInfo) {
      throw BagError(where + ": unknown record op " + std::to_string(op));
    }
    if (truncated)
      throw BagError(where + ": record data needs " + std::to_string(dlen) + " bytes, the file ends after " +
                     std::to_string(available) + " (truncated)");
  }
}

}  // namespace livo::import
