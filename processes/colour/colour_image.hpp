// A camera image as the colouring core sees it: decoded to 8-bit grey or RGB (OpenCV), with its
// stamp and exposure. Decoding never throws: a bad image gives an error string.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace livo {
namespace colour {

enum class Encoding : int { kGray8 = 0, kRgb8 = 1, kBgr8 = 2, kJpeg = 10, kPng = 11 };

/// An image as it arrives (raw bytes plus layout), independent of the message type.
struct RawImage {
  int64_t utime = 0;
  int width = 0, height = 0, row_stride = 0;
  int encoding = 0;
  float exposure_time = 0.0f;
  const uint8_t* data = nullptr;
  size_t size = 0;
};

struct ColourImage {
  int64_t utime = 0;
  float exposure_time = 0.0f;
  cv::Mat pixels;  // CV_8UC1 (grey) or CV_8UC3 (R, G, B)

  bool grey() const { return pixels.channels() == 1; }
  /// Bilinear sample at a pixel inside [0, w-1] x [0, h-1], as R, G, B (grey repeated).
  Eigen::Vector3f sample(const Eigen::Vector2d& pixel) const;
};

/// Decodes `raw`; false with `error` set if it is malformed, inconsistent or undecodable.
bool decodeImage(const RawImage& raw, ColourImage* out, std::string* error);

}  // namespace colour
}  // namespace livo
