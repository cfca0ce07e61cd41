// A camera image as the VIO uses it: decoded (GRAY8, RGB8, BGR8, JPEG, PNG) to 8-bit grey, and
// checked: the size the rig says, not all black, not blown out. Never throws: a bad image gives
// the reason.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

namespace livo::vio {

/// Encodings of image_t (kept equal to its constants; the core does not include LCM types).
enum class ImageEncoding : int { kGray8 = 0, kRgb8 = 1, kBgr8 = 2, kJpeg = 10, kPng = 11 };

/// An image as it arrives: raw bytes and their layout.
struct RawImage {
  int64_t utime = 0;
  int width = 0, height = 0, row_stride = 0;
  int encoding = 0;
  float exposure_time = 0.0f;  // s, 0 if unknown
  const uint8_t* data = nullptr;
  size_t size = 0;
};

struct GreyImage {
  int64_t utime = 0;           // image clock
  float exposure_time = 0.0f;  // s, 0 if unknown
  cv::Mat pixels;              // CV_8UC1
};

struct ImageCheckOptions {
  int dark_level = 10;               // grey levels at or below count as black
  int bright_level = 250;            // at or above count as saturated
  double max_dark_fraction = 0.95;   // more black pixels than this: "all black"
  double max_bright_fraction = 0.9;  // more saturated pixels than this: "blown out"
};

/// Decodes `raw` to grey; false with `why` if malformed, undecodable or of another size than
/// width x height (the rig's).
bool decodeGrey(const RawImage& raw, int width, int height, GreyImage* out, std::string* why);

/// "" if the image is usable, else why not (all black, blown out).
std::string imageProblem(const cv::Mat& grey, const ImageCheckOptions& options);

}  // namespace livo::vio
