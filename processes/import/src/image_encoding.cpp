#include "livo/import/image_encoding.hpp"

#include <algorithm>
#include <cstring>

#include "livo/import/stamp_conversion.hpp"

namespace livo::import {

namespace {
uint32_t be32(const uint8_t* p) {
  return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | p[3];
}
uint16_t be16(const uint8_t* p) { return static_cast<uint16_t>((p[0] << 8) | p[1]); }
}  // namespace

CompressedImageInfo sniffCompressedImage(const uint8_t* d, size_t n) {
  CompressedImageInfo info;
  static const uint8_t png[8] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
  if (n >= 8 && std::memcmp(d, png, 8) == 0) {
    info.encoding = image_t::ENCODING_PNG;
    if (n >= 24 && std::memcmp(d + 12, "IHDR", 4) == 0) {
      info.width = static_cast<int>(be32(d + 16));
      info.height = static_cast<int>(be32(d + 20));
      if (n >= 26) {
        static const int kChannels[7] = {1, 0, 3, 3, 2, 0, 4};  // by PNG colour type (3: palette, colour)
        info.channels = d[25] <= 6 ? kChannels[d[25]] : 0;
      }
    }
    return info;
  }
  if (n >= 3 && d[0] == 0xff && d[1] == 0xd8 && d[2] == 0xff) {
    info.encoding = image_t::ENCODING_JPEG;
    size_t i = 2;
    while (i + 4 <= n) {
      if (d[i] != 0xff) break;
      const uint8_t marker = d[i + 1];
      if (marker == 0xff) {
        ++i;
        continue;
      }
      if (marker == 0xd8 || (marker >= 0xd0 && marker <= 0xd7) || marker == 0x01) {
        i += 2;
        continue;
      }
      const uint16_t len = be16(d + i + 2);
      const bool sof = marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
      if (sof && i + 9 <= n) {
        info.height = be16(d + i + 5);
        info.width = be16(d + i + 7);
        if (i + 10 <= n) info.channels = d[i + 9];  // Nf: 1 grey, 3 YCbCr, 4 CMYK
        break;
      }
      if (marker == 0xda || len < 2) break;  // start of scan: no frame header before it
      i += 2 + len;
    }
  }
  return info;
}

namespace {

/// A raw (or depth) image's pixels, `bytes_per_pixel` each, with its stamp, frame and size; throws
/// unless a row of `step` bytes holds the width and the data holds every row.
image_t rawImage(const RosImage& m, int8_t encoding, uint64_t bytes_per_pixel, const std::string& frame,
                 const std::string& where) {
  if (static_cast<uint64_t>(m.step) < static_cast<uint64_t>(m.width) * bytes_per_pixel)
    throw DecodeError(where + ": field 'step': " + std::to_string(m.step) + " is less than width * " +
                      std::to_string(bytes_per_pixel));
  const uint64_t size = static_cast<uint64_t>(m.step) * m.height;
  if (size > m.data_size)
    throw DecodeError(where + ": field 'data': " + std::to_string(m.data_size) + " bytes, step * height needs " +
                      std::to_string(size));
  image_t img;
  img.utime = nsToUtime(m.header.stampNs());
  img.frame = frame;
  img.width = static_cast<int32_t>(m.width);
  img.height = static_cast<int32_t>(m.height);
  img.row_stride = static_cast<int32_t>(m.step);
  img.encoding = encoding;
  img.exposure_time = 0.0f;
  img.size = static_cast<int32_t>(size);
  img.data.assign(m.data, m.data + size);
  return img;
}

}  // namespace

image_t convertRosImage(const RosImage& m, const std::string& frame, const std::string& where) {
  if (m.encoding == "mono8" || m.encoding == "8UC1") return rawImage(m, image_t::ENCODING_GRAY8, 1, frame, where);
  if (m.encoding == "rgb8") return rawImage(m, image_t::ENCODING_RGB8, 3, frame, where);
  if (m.encoding == "bgr8" || m.encoding == "8UC3") return rawImage(m, image_t::ENCODING_BGR8, 3, frame, where);
  if (isRosDepthEncoding(m.encoding))
    throw DecodeError(where + ": field 'encoding': '" + m.encoding +
                      "' is depth, not a camera image (map the topic with --depth)");
  throw DecodeError(where + ": field 'encoding': '" + m.encoding +
                    "' is not supported (mono8, rgb8, bgr8, 8UC1, 8UC3)");
}

bool isRosDepthEncoding(const std::string& encoding) {
  return encoding == "16UC1" || encoding == "mono16" || encoding == "32FC1";
}

image_t convertRosDepthImage(const RosImage& m, const std::string& frame, const std::string& where) {
  if (!isRosDepthEncoding(m.encoding))
    throw DecodeError(where + ": field 'encoding': '" + m.encoding + "' is not depth (16UC1 in mm, 32FC1 in m)");
  const bool metres = m.encoding == "32FC1";
  const uint64_t bytes = metres ? 4 : 2;
  image_t img = rawImage(m, metres ? image_t::ENCODING_DEPTH32F : image_t::ENCODING_DEPTH16, bytes, frame, where);
  if (m.is_bigendian) {
    for (uint32_t y = 0; y < m.height; ++y) {
      uint8_t* row = img.data.data() + static_cast<size_t>(y) * m.step;
      for (uint64_t x = 0; x < m.width; ++x) std::reverse(row + x * bytes, row + (x + 1) * bytes);
    }
  }
  return img;
}

image_t convertRosCompressedImage(const RosCompressedImage& m, const std::string& frame, const std::string& where) {
  const CompressedImageInfo info = sniffCompressedImage(m.data, m.data_size);
  if (info.encoding < 0) throw DecodeError(where + ": field 'data': neither JPEG nor PNG (format '" + m.format + "')");
  image_t img;
  img.utime = nsToUtime(m.header.stampNs());
  img.frame = frame;
  img.width = info.width;
  img.height = info.height;
  img.row_stride = 0;
  img.encoding = info.encoding;
  img.exposure_time = 0.0f;
  img.size = static_cast<int32_t>(m.data_size);
  img.data.assign(m.data, m.data + m.data_size);
  return img;
}

}  // namespace livo::import
