#include "livo/colour/colour_image.hpp"

#include <algorithm>
#include <cmath>

namespace livo::colour {

Eigen::Vector3f ColourImage::sample(const Eigen::Vector2d& pixel) const {
  const int x0 = std::min(static_cast<int>(std::floor(pixel.x())), pixels.cols - 2);
  const int y0 = std::min(static_cast<int>(std::floor(pixel.y())), pixels.rows - 2);
  const float ax = static_cast<float>(pixel.x() - x0), ay = static_cast<float>(pixel.y() - y0);
  const float w00 = (1 - ax) * (1 - ay), w10 = ax * (1 - ay), w01 = (1 - ax) * ay, w11 = ax * ay;
  if (grey()) {
    const uint8_t* r0 = pixels.ptr<uint8_t>(y0) + x0;
    const uint8_t* r1 = pixels.ptr<uint8_t>(y0 + 1) + x0;
    const float g = w00 * r0[0] + w10 * r0[1] + w01 * r1[0] + w11 * r1[1];
    return Eigen::Vector3f::Constant(g);
  }
  const uint8_t* r0 = pixels.ptr<uint8_t>(y0) + 3 * x0;
  const uint8_t* r1 = pixels.ptr<uint8_t>(y0 + 1) + 3 * x0;
  Eigen::Vector3f c;
  for (int k = 0; k < 3; ++k) c[k] = w00 * r0[k] + w10 * r0[3 + k] + w01 * r1[k] + w11 * r1[3 + k];
  return c;
}

bool decodeColourImage(const RawImage& raw, int width, int height, ColourImage* out, std::string* error) {
  if (width < 2 || height < 2) {
    *error = "image smaller than 2x2 pixels";
    return false;
  }
  if (!decodeImage(raw, width, height, PixelFormat::kGreyOrRgb, &out->pixels, error)) return false;
  out->utime = raw.utime;
  out->exposure_time = exposureTime(raw);
  return true;
}

}  // namespace livo::colour
