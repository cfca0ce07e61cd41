#include "colour_image.hpp"

#include <cmath>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace livo {
namespace colour {

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

bool decodeImage(const RawImage& raw, ColourImage* out, std::string* error) {
  out->utime = raw.utime;
  out->exposure_time = std::isfinite(raw.exposure_time) && raw.exposure_time > 0 ? raw.exposure_time : 0.0f;
  const auto enc = static_cast<Encoding>(raw.encoding);
  if (enc == Encoding::kJpeg || enc == Encoding::kPng) {
    if (raw.size == 0 || raw.data == nullptr) {
      *error = "empty compressed image";
      return false;
    }
    const cv::Mat buf(1, static_cast<int>(raw.size), CV_8UC1, const_cast<uint8_t*>(raw.data));
    cv::Mat img;
    try {
      img = cv::imdecode(buf, cv::IMREAD_UNCHANGED);
    } catch (const cv::Exception& e) {
      *error = std::string("decode failed: ") + e.what();
      return false;
    }
    if (img.empty()) {
      *error = "image does not decode";
      return false;
    }
    if (img.depth() != CV_8U) img.convertTo(img, CV_8U, img.depth() == CV_16U ? 1.0 / 257.0 : 1.0);
    if (img.channels() == 1) {
      out->pixels = img;
    } else if (img.channels() == 3) {
      cv::cvtColor(img, out->pixels, cv::COLOR_BGR2RGB);
    } else if (img.channels() == 4) {
      cv::cvtColor(img, out->pixels, cv::COLOR_BGRA2RGB);
    } else {
      *error = "unsupported channel count";
      return false;
    }
    if (out->pixels.cols < 2 || out->pixels.rows < 2) {
      *error = "image too small";
      return false;
    }
    return true;
  }
  int channels = 0;
  if (enc == Encoding::kGray8) channels = 1;
  else if (enc == Encoding::kRgb8 || enc == Encoding::kBgr8) channels = 3;
  else {
    *error = "unknown encoding " + std::to_string(raw.encoding);
    return false;
  }
  if (raw.width < 2 || raw.height < 2 || raw.width > 100000 || raw.height > 100000) {
    *error = "bad image size";
    return false;
  }
  const size_t stride = raw.row_stride > 0 ? static_cast<size_t>(raw.row_stride) : static_cast<size_t>(raw.width) * channels;
  if (stride < static_cast<size_t>(raw.width) * channels || raw.data == nullptr ||
      raw.size < stride * static_cast<size_t>(raw.height - 1) + static_cast<size_t>(raw.width) * channels) {
    *error = "image data shorter than width x height";
    return false;
  }
  const cv::Mat view(raw.height, raw.width, channels == 1 ? CV_8UC1 : CV_8UC3, const_cast<uint8_t*>(raw.data), stride);
  if (enc == Encoding::kBgr8) cv::cvtColor(view, out->pixels, cv::COLOR_BGR2RGB);
  else out->pixels = view.clone();
  return true;
}

}  // namespace colour
}  // namespace livo
