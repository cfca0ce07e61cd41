// A camera image as the VIO uses it: decoded to 8-bit grey by the shared decoder
// (livo/camera_image.hpp: GRAY8, RGB8, BGR8, JPEG, PNG; the size the rig says), then checked with
// the VIO's own policy: not all black, not blown out. Never throws: a bad image gives the reason.
#pragma once

#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

#include "livo/camera_image.hpp"

namespace livo::vio {

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

/// "" if the image is usable, else why not (all black, blown out).
std::string imageProblem(const cv::Mat& grey, const ImageCheckOptions& options);

/// Decodes `raw` to grey (livo::decodeGrey) and checks it (imageProblem); false with `why` if it
/// is malformed, undecodable, not width x height (the rig's camera) or unusable. `out` has the
/// stamp and exposure time even then, and the pixels if they decoded.
bool readGreyImage(const RawImage& raw, int width, int height, const ImageCheckOptions& checks, GreyImage* out,
                   std::string* why);

}  // namespace livo::vio
