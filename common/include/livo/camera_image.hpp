// Camera images (image_t) decoded to 8-bit grey or RGB, and depth images to metres, with OpenCV,
// for every process that reads the camera. Target livo_camera_image, apart from livo_common so
// that livo_common needs no OpenCV.
// Decoding never throws: a malformed, undecodable or wrongly sized image gives the reason.
// What a process then refuses (black, blown out, ...) or does with the exposure time is its own.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

namespace livo {

class image_t;  // livo/image_t.hpp (lcm-gen)

/// The encodings of image_t (equal to its ENCODING_* constants).
enum class ImageEncoding : int {
  kGray8 = 0,
  kRgb8 = 1,
  kBgr8 = 2,
  kJpeg = 10,
  kPng = 11,
  kDepth16 = 20,   // uint16 millimetres, 0: no depth
  kDepth32f = 21,  // float32 metres, 0 or NaN: no depth
};

/// An image as it arrives: its bytes and their layout, independent of the message type.
struct RawImage {
  int64_t utime = 0;
  int width = 0, height = 0;   // raw encodings: the layout; compressed: not used (the data has it)
  int row_stride = 0;          // bytes per row of raw encodings; 0: rows packed
  int encoding = 0;            // ImageEncoding
  float exposure_time = 0.0f;  // s, as sent (see exposureTime)
  const uint8_t* data = nullptr;
  size_t size = 0;
};

/// A view of the message's bytes (valid while `m` lives); size = min(m.size, m.data.size()).
RawImage rawImage(const image_t& m);

/// The exposure time in s; 0 (unknown) if the image carries none or one not finite and positive.
float exposureTime(const RawImage& raw);

/// What the decoder produces.
enum class PixelFormat {
  kGrey,       // CV_8UC1: colour converted to luminance (0.299 R + 0.587 G + 0.114 B)
  kRgb,        // CV_8UC3, channels R, G, B: grey repeated in all three
  kGreyOrRgb,  // grey images CV_8UC1, colour ones CV_8UC3 (R, G, B): nothing made up, nothing lost
};

/// Decodes GRAY8, RGB8, BGR8 (rows `row_stride` bytes apart, 0: packed) or JPEG / PNG (8 or 16
/// bit, 1, 3 or 4 channels; alpha dropped, 16 bit scaled to 8) into `out`, its own copy of the
/// pixels. False with `why` set and `out` untouched if the encoding is unknown, the raw data is
/// shorter than its layout, the compressed data is not what the encoding says, is cut off (a JPEG
/// must end with its end-of-image marker; zero padding after it is fine) or does not decode, or
/// the image is not `width` x `height` (the camera's size; `why` then names both as WxH). A depth
/// image (DEPTH16, DEPTH32F) is refused: it is not a picture (see decodeDepth).
bool decodeImage(const RawImage& raw, int width, int height, PixelFormat format, cv::Mat* out, std::string* why);

/// decodeImage to PixelFormat::kGrey.
inline bool decodeGrey(const RawImage& raw, int width, int height, cv::Mat* out, std::string* why) {
  return decodeImage(raw, width, height, PixelFormat::kGrey, out, why);
}
/// decodeImage to PixelFormat::kRgb.
inline bool decodeRgb(const RawImage& raw, int width, int height, cv::Mat* out, std::string* why) {
  return decodeImage(raw, width, height, PixelFormat::kRgb, out, why);
}

/// Decodes a depth image registered to a camera, DEPTH16 (mm), DEPTH32F (m) or a 16-bit grey PNG
/// (mm, as ROS and the RGB-D datasets store depth), into `out`: CV_32FC1, z along the optical axis
/// in metres, 0 where there is no depth (0, NaN, infinities and negative values as sent). Its own
/// copy. False with `why` set and `out` untouched on the same grounds as decodeImage, and for an
/// encoding that is not depth (a GRAY8 image, an 8-bit or colour PNG).
bool decodeDepth(const RawImage& raw, int width, int height, cv::Mat* out, std::string* why);

}  // namespace livo
