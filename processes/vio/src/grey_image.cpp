#include "livo/vio/grey_image.hpp"

#include <cmath>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace livo::vio {

namespace {
std::string sizeText(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }
}  // namespace

bool decodeGrey(const RawImage& raw, int width, int height, GreyImage* out, std::string* why) {
  out->utime = raw.utime;
  out->exposure_time = std::isfinite(raw.exposure_time) && raw.exposure_time > 0.0f ? raw.exposure_time : 0.0f;
  const auto enc = static_cast<ImageEncoding>(raw.encoding);
  if (enc == ImageEncoding::kJpeg || enc == ImageEncoding::kPng) {
    if (raw.data == nullptr || raw.size == 0) {
      *why = "empty compressed image";
      return false;
    }
    const cv::Mat buf(1, static_cast<int>(raw.size), CV_8UC1, const_cast<uint8_t*>(raw.data));
    cv::Mat img;
    try {
      img = cv::imdecode(buf, cv::IMREAD_GRAYSCALE);
    } catch (const cv::Exception& e) {
      *why = std::string("image does not decode: ") + e.what();
      return false;
    }
    if (img.empty()) {
      *why = "image does not decode";
      return false;
    }
    if (img.depth() != CV_8U) img.convertTo(img, CV_8U, img.depth() == CV_16U ? 1.0 / 257.0 : 1.0);
    if (img.cols != width || img.rows != height) {
      *why = "image is " + sizeText(img.cols, img.rows) + ", the rig's camera " + sizeText(width, height);
      return false;
    }
    out->pixels = img;
    return true;
  }
  int channels = 0;
  if (enc == ImageEncoding::kGray8) channels = 1;
  else if (enc == ImageEncoding::kRgb8 || enc == ImageEncoding::kBgr8) channels = 3;
  else {
    *why = "unknown image encoding " + std::to_string(raw.encoding);
    return false;
  }
  if (raw.width != width || raw.height != height) {
    *why = "image is " + sizeText(raw.width, raw.height) + ", the rig's camera " + sizeText(width, height);
    return false;
  }
  const size_t row = static_cast<size_t>(width) * channels;
  const size_t stride = raw.row_stride > 0 ? static_cast<size_t>(raw.row_stride) : row;
  if (stride < row || raw.data == nullptr || raw.size < stride * static_cast<size_t>(height - 1) + row) {
    *why = "image data shorter than its width x height";
    return false;
  }
  const cv::Mat view(height, width, channels == 1 ? CV_8UC1 : CV_8UC3, const_cast<uint8_t*>(raw.data), stride);
  if (enc == ImageEncoding::kGray8) out->pixels = view.clone();
  else cv::cvtColor(view, out->pixels, enc == ImageEncoding::kRgb8 ? cv::COLOR_RGB2GRAY : cv::COLOR_BGR2GRAY);
  return true;
}

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

}  // namespace livo::vio
