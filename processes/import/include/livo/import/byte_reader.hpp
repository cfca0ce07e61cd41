// Bounds-checked little-endian reading of a byte buffer. Every read names the field it reads, so
// a short or corrupt buffer gives "<context>: field 'x': needs 8 bytes at offset 120, 4 left".
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

namespace livo::import {

class DecodeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ByteReader {
 public:
  ByteReader(const uint8_t* data, size_t size, std::string context = "")
      : data_(data), size_(size), context_(std::move(context)) {}

  uint8_t u8(const char* field) { return get<uint8_t>(field); }
  uint16_t u16(const char* field) { return get<uint16_t>(field); }
  uint32_t u32(const char* field) { return get<uint32_t>(field); }
  uint64_t u64(const char* field) { return get<uint64_t>(field); }
  int32_t i32(const char* field) { return get<int32_t>(field); }
  float f32(const char* field) { return get<float>(field); }
  double f64(const char* field) { return get<double>(field); }

  /// n raw bytes (a pointer into the buffer).
  const uint8_t* bytes(size_t n, const char* field) {
    need(n, field);
    const uint8_t* p = data_ + pos_;
    pos_ += n;
    return p;
  }
  /// ROS string / uint8[]: uint32 length, then the bytes.
  std::string string(const char* field) {
    const uint32_t n = u32(field);
    const uint8_t* p = bytes(n, field);
    return std::string(reinterpret_cast<const char*>(p), n);
  }
  /// Length of a variable array whose elements take at least `min_element_bytes` each; checked
  /// against what is left so that a corrupt length cannot make the caller allocate gigabytes.
  uint32_t arrayLength(const char* field, size_t min_element_bytes) {
    const uint32_t n = u32(field);
    if (min_element_bytes && static_cast<uint64_t>(n) * min_element_bytes > remaining())
      fail(field, "array of " + std::to_string(n) + " elements does not fit in the " + std::to_string(remaining()) +
                      " bytes left");
    return n;
  }
  void skip(size_t n, const char* field) { bytes(n, field); }
  /// A fixed array of n float64 (covariances).
  void skipF64(size_t n, const char* field) { bytes(n * 8, field); }

  size_t position() const { return pos_; }
  size_t remaining() const { return size_ - pos_; }
  size_t size() const { return size_; }
  const std::string& context() const { return context_; }
  [[noreturn]] void fail(const char* field, const std::string& what) const {
    throw DecodeError((context_.empty() ? "" : context_ + ": ") + "field '" + field + "': " + what);
  }

 private:
  template <class T>
  T get(const char* field) {
    need(sizeof(T), field);
    T v;
    std::memcpy(&v, data_ + pos_, sizeof(T));  // the host is little-endian (x86-64, arm64)
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
  std::string context_;
};

}  // namespace livo::import
