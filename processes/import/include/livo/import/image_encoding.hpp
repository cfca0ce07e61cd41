// Images as the log carries them: raw GRAY8 / RGB8 / BGR8, or JPEG / PNG kept compressed with
// their size read from the file's own header (PNG IHDR, JPEG SOFn marker).
#pragma once

#include <cstdint>
#include <string>

#include "livo/image_t.hpp"
#include "livo/import/ros_messages.hpp"

namespace livo::import {

struct CompressedImageInfo {
  int8_t encoding = -1;  // image_t::ENCODING_JPEG or ENCODING_PNG, -1 if neither
  int width = 0, height = 0;
  int channels = 0;  // colour channels: 1 grey, 3 colour (4 with alpha); 0 if the header is cut short
};
/// Recognises PNG and JPEG by their signature; width/height 0 if the header is cut short.
CompressedImageInfo sniffCompressedImage(const uint8_t* data, size_t size);

/// sensor_msgs/Image -> image_t. mono8/8UC1 -> GRAY8, rgb8 -> RGB8, bgr8/8UC3 -> BGR8; the
/// row stride (step) is kept. Throws DecodeError naming `where` for other encodings or short data.
image_t convertRosImage(const RosImage& m, const std::string& frame, const std::string& where);
/// Depth encodings of sensor_msgs/Image: 16UC1 (and mono16, as some drivers label it), millimetres;
/// 32FC1, metres (REP 118).
bool isRosDepthEncoding(const std::string& encoding);
/// A depth sensor_msgs/Image -> image_t: 16UC1 / mono16 -> DEPTH16, 32FC1 -> DEPTH32F, the row
/// stride kept and big-endian data swapped to little-endian. Throws DecodeError naming `where`
/// for other encodings or short data.
image_t convertRosDepthImage(const RosImage& m, const std::string& frame, const std::string& where);
/// sensor_msgs/CompressedImage -> image_t kept compressed. Throws DecodeError if the data is
/// neither JPEG nor PNG.
image_t convertRosCompressedImage(const RosCompressedImage& m, const std::string& frame, const std::string& where);

}  // namespace livo::import
