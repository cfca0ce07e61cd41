// A camera image as the colouring core sees it: 8-bit grey or RGB, with its stamp and exposure.
// Decoding is the shared one (livo/camera_image.hpp); it never throws: a bad image gives an error
// string.
#pragma once

#include <cstdint>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "livo/camera_image.hpp"

namespace livo::colour {

struct ColourImage {
  int64_t utime = 0;
  float exposure_time = 0.0f;
  cv::Mat pixels;  // CV_8UC1 (grey) or CV_8UC3 (R, G, B)

  bool grey() const { return pixels.channels() == 1; }
  /// Bilinear sample at a pixel inside [0, w-1] x [0, h-1], as R, G, B (grey repeated).
  Eigen::Vector3f sample(const Eigen::Vector2d& pixel) const;
};

/// Decodes `raw` with livo::decodeImage (grey images stay grey, colour ones become R, G, B) and
/// takes its stamp and exposure time (0 if unknown); false with `error` set if it is malformed,
/// undecodable, not width x height (the rig's camera) or smaller than the 2x2 sample() needs.
bool decodeColourImage(const RawImage& raw, int width, int height, ColourImage* out, std::string* error);

}  // namespace livo::colour
