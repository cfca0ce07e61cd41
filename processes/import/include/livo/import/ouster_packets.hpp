// Ouster UDP packets (firmware 2.x): LiDAR packets in the LEGACY profile and the eUDP profiles
// RNG19_RFL8_SIG16_NIR16, RNG19_RFL8_SIG16_NIR16_DUAL (first return) and RNG15_RFL8_NIR8
// (low data rate), and the 48-byte IMU packet.
//  LEGACY:  no packet header; per column a 16-byte header (timestamp u64 ns, measurement_id u16,
//           frame_id u16, encoder u32), 12 bytes per pixel (range u32 & 0xFFFFF mm,
//           reflectivity u16, signal u16, near-IR u16), a u32 status (0xFFFFFFFF = valid).
//  eUDP:    32-byte packet header (packet_type u16, frame_id u16, ...), per column a 12-byte header
//           (timestamp u64 ns, measurement_id u16, status u16, bit 0 = valid), then pixels
//           (RNG19...: range u32 & 0x7FFFF mm, reflectivity u8 at 4, signal u16 at 6, 12 bytes;
//            DUAL: range u32 & 0x7FFFF, reflectivity u8 at 3, signal u16 at 8, 16 bytes;
//            RNG15_RFL8_NIR8: range (u16 & 0x7FFF) * 8 mm, reflectivity u8 at 2, 4 bytes),
//           then a 32-byte packet footer.
//  IMU:     sys/accel/gyro timestamps (u64 ns), acceleration xyz (float, g), angular rate xyz
//           (float, deg/s).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "livo/import/ouster_metadata.hpp"

namespace livo::import {

struct OusterColumn {
  int64_t timestamp_ns = 0;
  int measurement_id = 0;
  bool valid = false;
  std::vector<uint32_t> range_mm;  // per beam, 0 = no return
  std::vector<uint16_t> reflectivity;
  std::vector<uint16_t> signal;
};

struct OusterLidarPacket {
  int frame_id = 0;
  std::vector<OusterColumn> columns;
};

class OusterPacketFormat {
 public:
  /// Throws std::invalid_argument for an unsupported profile.
  explicit OusterPacketFormat(const OusterMetadata& metadata);
  size_t lidarPacketSize() const { return packet_size_; }
  /// Decodes a LiDAR packet; throws std::runtime_error naming the field if the size is wrong.
  OusterLidarPacket decodeLidar(const uint8_t* data, size_t size) const;

 private:
  bool legacy_ = true;
  int pixels_, columns_;
  size_t pixel_bytes_, column_header_, column_bytes_, packet_header_, packet_size_;
  enum class Pixel { kLegacy, kSingle, kDual, kLowDataRate } pixel_;
};

struct OusterImuPacket {
  int64_t sys_ts_ns = 0, accel_ts_ns = 0, gyro_ts_ns = 0;
  float accel_g[3] = {0, 0, 0};
  float gyro_deg_s[3] = {0, 0, 0};
};
/// Throws std::runtime_error if the packet is not 48 bytes.
OusterImuPacket decodeOusterImu(const uint8_t* data, size_t size);

}  // namespace livo::import
