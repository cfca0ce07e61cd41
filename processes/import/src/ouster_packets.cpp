#include "livo/import/ouster_packets.hpp"

#include <cstring>
#include <stdexcept>

namespace livo::import {

namespace {
template <class T>
T le(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}
}  // namespace

OusterPacketFormat::OusterPacketFormat(const OusterMetadata& m)
    : pixels_(m.pixels_per_column), columns_(m.columns_per_packet) {
  const std::string& p = m.udp_profile_lidar;
  if (p == "LEGACY") {
    pixel_ = Pixel::kLegacy, pixel_bytes_ = 12;
  } else if (p == "RNG19_RFL8_SIG16_NIR16") {
    pixel_ = Pixel::kSingle, pixel_bytes_ = 12;
  } else if (p == "RNG19_RFL8_SIG16_NIR16_DUAL") {
    pixel_ = Pixel::kDual, pixel_bytes_ = 16;
  } else if (p == "RNG15_RFL8_NIR8") {
    pixel_ = Pixel::kLowDataRate, pixel_bytes_ = 4;
  } else {
    throw std::invalid_argument("udp_profile_lidar '" + p +
                                "' is not supported (LEGACY, RNG19_RFL8_SIG16_NIR16, "
                                "RNG19_RFL8_SIG16_NIR16_DUAL, RNG15_RFL8_NIR8)");
  }
  legacy_ = pixel_ == Pixel::kLegacy;
  column_header_ = legacy_ ? 16 : 12;
  column_bytes_ = column_header_ + pixels_ * pixel_bytes_ + (legacy_ ? 4 : 0);
  packet_header_ = legacy_ ? 0 : 32;
  packet_size_ = packet_header_ + columns_ * column_bytes_ + (legacy_ ? 0 : 32);
}

OusterLidarPacket OusterPacketFormat::decodeLidar(const uint8_t* d, size_t n) const {
  if (n != packet_size_)
    throw std::runtime_error("LiDAR packet of " + std::to_string(n) + " bytes, the metadata's profile needs " +
                             std::to_string(packet_size_));
  OusterLidarPacket out;
  if (!legacy_) out.frame_id = le<uint16_t>(d + 2);
  out.columns.resize(columns_);
  for (int c = 0; c < columns_; ++c) {
    const uint8_t* col = d + packet_header_ + c * column_bytes_;
    OusterColumn& oc = out.columns[c];
    oc.timestamp_ns = static_cast<int64_t>(le<uint64_t>(col));
    oc.measurement_id = le<uint16_t>(col + 8);
    if (legacy_) {
      if (c == 0) out.frame_id = le<uint16_t>(col + 10);
      oc.valid = le<uint32_t>(col + column_bytes_ - 4) == 0xffffffffu;
    } else {
      oc.valid = (le<uint16_t>(col + 10) & 0x1) != 0;
    }
    oc.range_mm.resize(pixels_), oc.reflectivity.resize(pixels_), oc.signal.resize(pixels_);
    for (int i = 0; i < pixels_; ++i) {
      const uint8_t* px = col + column_header_ + i * pixel_bytes_;
      switch (pixel_) {
        case Pixel::kLegacy:
          oc.range_mm[i] = le<uint32_t>(px) & 0xfffffu;
          oc.reflectivity[i] = le<uint16_t>(px + 4);
          oc.signal[i] = le<uint16_t>(px + 6);
          break;
        case Pixel::kSingle:
          oc.range_mm[i] = le<uint32_t>(px) & 0x7ffffu;
          oc.reflectivity[i] = px[4];
          oc.signal[i] = le<uint16_t>(px + 6);
          break;
        case Pixel::kDual:
          oc.range_mm[i] = le<uint32_t>(px) & 0x7ffffu;
          oc.reflectivity[i] = px[3];
          oc.signal[i] = le<uint16_t>(px + 8);
          break;
        case Pixel::kLowDataRate:
          oc.range_mm[i] = static_cast<uint32_t>(le<uint16_t>(px) & 0x7fffu) * 8u;
          oc.reflectivity[i] = px[2];
          oc.signal[i] = 0;
          break;
      }
    }
  }
  return out;
}

OusterImuPacket decodeOusterImu(const uint8_t* d, size_t n) {
  if (n != 48) throw std::runtime_error("IMU packet of " + std::to_string(n) + " bytes, expected 48");
  OusterImuPacket p;
  p.sys_ts_ns = static_cast<int64_t>(le<uint64_t>(d));
  p.accel_ts_ns = static_cast<int64_t>(le<uint64_t>(d + 8));
  p.gyro_ts_ns = static_cast<int64_t>(le<uint64_t>(d + 16));
  for (int i = 0; i < 3; ++i) {
    p.accel_g[i] = le<float>(d + 24 + 4 * i);
    p.gyro_deg_s[i] = le<float>(d + 36 + 4 * i);
  }
  return p;
}

}  // namespace livo::import
