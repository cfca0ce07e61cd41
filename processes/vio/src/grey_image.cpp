#include "livo/vio/grey_image.hpp"

namespace livo::vio {

std::string imageProblem(const cv::Mat& grey, const ImageCheckOptions& o) {
  // every second pixel of every second row: plenty for fractions, a quarter of the cost
  size_t dark = 0, bright = 0, n = 0;
  for (int y = 0; y < grey.rows; y += 2) {
    const uint8_t* row = grey.ptr<uint8_t>(y);
    for (int x = 0; x < grey.cols; x += 2, ++n) {
      dark += row[x] <= o.dark_level;
      bright += row[x] >= o.bright_level;
    }
  }
  if (n == 0) return "empty image";
  if (static_cast<double>(dark) > o.max_dark_fraction * n)
    return "image is black (" + std::to_string(100 * dark / n) + " % of pixels at or below " +
           std::to_string(o.dark_level) + ")";
  if (static_cast<double>(bright) > o.max_bright_fraction * n)
    return "image is blown out (" + std::to_string(100 * bright / n) + " % of pixels at or above " +
           std::to_string(o.bright_level) + ")";
  return "";
}

bool readGreyImage(const RawImage& raw, int width, int height, const ImageCheckOptions& checks, GreyImage* out,
                   std::string* why) {
  out->utime = raw.utime;
  out->exposure_time = exposureTime(raw);
  if (!decodeGrey(raw, width, height, &out->pixels, why)) return false;
  *why = imageProblem(out->pixels, checks);
  return why->empty();
}

}  // namespace livo::vio
