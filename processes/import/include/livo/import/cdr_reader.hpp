// Bounds-checked reading of a ROS 2 message in CDR (XCDR1, "plain" CDR as rosbag2 stores it): a
// 4-byte encapsulation header (0x00 0x00 big-endian, 0x00 0x01 little-endian; the options bytes
// are ignored), then each primitive aligned to its size relative to the byte after the header.
// Strings carry a uint32 length that counts their terminating NUL; sequences a uint32 count.
// Same interface as ByteReader, so the message decoders are written once for both wire formats;
// every read names its field, so a short or corrupt message gives
// "<context>: field 'x': needs 8 bytes at offset 120, 4 left".
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <utility>

#include "livo/import/byte_reader.hpp"

namespace livo::import {

class CdrReader {
 public:
  /// `data` is the whole serialised message, encapsulation header included. Throws DecodeError
  /// for a header that is not plain CDR (XCDR2 and parameter lists are not what rosbag2 writes).
  CdrReader(const uint8_t* data, size_t size, std::string context = "")
      : data_(data), size_(size), context_(std::move(context)) {
    need(4, "encapsulation header");
    if (data_[0] != 0 || data_[1] > 1)
      fail("encapsulation header",
           "representation 0x" + hex(data_[0]) + hex(data_[1]) + " is not plain CDR (0x0000 or 0x0001)");
    big_endian_ = data_[1] == 0;
    pos_ = 4;
  }

  uint8_t u8(const char* field) { return get<uint8_t>(field); }
  uint16_t u16(const char* field) { return get<uint16_t>(field); }
  uint32_t u32(const char* field) { return get<uint32_t>(field); }
  uint64_t u64(const char* field) { return get<uint64_t>(field); }
  int32_t i32(const char* field) { return get<int32_t>(field); }
  float f32(const char* field) { return get<float>(field); }
  double f64(const char* field) { return get<double>(field); }

  /// n raw bytes (a pointer into the buffer), no alignment (octet sequences, uint8[n]).
  const uint8_t* bytes(size_t n, const char* field) {
    need(n, field);
    const uint8_t* p = data_ + pos_;
    pos_ += n;
    return p;
  }
  /// CDR string: uint32 length including the NUL, the characters, the NUL (a length of 0, which
  /// some writers use for "", is accepted).
  std::string string(const char* field) {
    const uint32_t n = u32(field);
    const uint8_t* p = bytes(n, field);
    if (n == 0) return std::string();
    if (p[n - 1] != 0) fail(field, "string of " + std::to_string(n) + " bytes does not end with its NUL");
    return std::string(reinterpret_cast<const char*>(p), n - 1);
  }
  /// Count of a sequence whose elements take at least `min_element_bytes` each, checked against
  /// what is left (a corrupt count cannot make the caller allocate gigabytes).
  uint32_t arrayLength(const char* field, size_t min_element_bytes) {
    const uint32_t n = u32(field);
    if (min_element_bytes && static_cast<uint64_t>(n) * min_element_bytes > remaining())
      fail(field, "sequence of " + std::to_string(n) + " elements does not fit in the " +
                      std::to_string(remaining()) + " bytes left");
    return n;
  }
  /// A fixed array of n float64 (covariances), aligned as its elements.
  void skipF64(size_t n, const char* field) {
    align(8, field);
    bytes(n * 8, field);
  }

  bool bigEndian() const { return big_endian_; }
  size_t position() const { return pos_; }
  size_t remaining() const { return size_ - pos_; }
  size_t size() const { return size_; }
  const std::string& context() const { return context_; }
  [[noreturn]] void fail(const char* field, const std::string& what) const {
    throw DecodeError((context_.empty() ? "" : context_ + ": ") + "field '" + field + "': " + what);
  }

 private:
  static std::string hex(uint8_t b) {
    const char* d = "0123456789abcdef";
    return {d[b >> 4], d[b & 15]};
  }
  void align(size_t n, const char* field) {
    const size_t pad = (n - (pos_ - 4) % n) % n;
    need(pad, field);
    pos_ += pad;
  }
  template <class T>
  T get(const char* field) {
    align(sizeof(T), field);
    need(sizeof(T), field);
    uint8_t b[sizeof(T)];
    std::memcpy(b, data_ + pos_, sizeof(T));
    if (big_endian_)  // the host is little-endian (x86-64, arm64)
      for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    T v;
    std::memcpy(&v, b, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  void need(size_t n, const char* field) const {
    if (n > remaining())
      fail(field, "needs " + std::to_string(n) + " bytes at offset " + std::to_string(pos_) + ", " +
                      std::to_string(remaining()) + " left (truncated?)");
  }

  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
  bool big_endian_ = false;
  std::string context_;
};

}  // namespace livo::import
