#include "livo/vio/image_pyramid.hpp"

#include <algorithm>
#include <cmath>

namespace livo::vio {

void ImagePyramid::build(const cv::Mat& grey, int levels) {
  levels_.resize(static_cast<size_t>(std::max(1, levels)));
  levels_[0] = grey;
  for (size_t l = 1; l < levels_.size(); ++l) {
    const cv::Mat& src = levels_[l - 1];
    const int w = src.cols / 2, h = src.rows / 2;
    cv::Mat& dst = levels_[l];
    dst.create(h, w, CV_8UC1);
    for (int y = 0; y < h; ++y) {
      const uint8_t* r0 = src.ptr<uint8_t>(2 * y);
      const uint8_t* r1 = src.ptr<uint8_t>(2 * y + 1);
      uint8_t* d = dst.ptr<uint8_t>(y);
      for (int x = 0; x < w; ++x)
        d[x] = static_cast<uint8_t>((r0[2 * x] + r0[2 * x + 1] + r1[2 * x] + r1[2 * x + 1] + 2) >> 2);
    }
  }
}

bool ImagePyramid::sampleGrid(int level, const Eigen::Vector2d& centre, int n, float* out) const {
  const cv::Mat& img = levels_[level];
  const double half = 0.5 * (n - 1);
  const double x0 = centre.x() - half, y0 = centre.y() - half;
  if (!(x0 >= 0.0 && y0 >= 0.0)) return false;  // also rejects NaN
  const int ix = static_cast<int>(x0), iy = static_cast<int>(y0);
  if (ix + n >= img.cols || iy + n >= img.rows) return false;  // needs columns ix .. ix + n
  const float ax = static_cast<float>(x0 - ix), ay = static_cast<float>(y0 - iy);
  const float w00 = (1 - ax) * (1 - ay), w10 = ax * (1 - ay), w01 = (1 - ax) * ay, w11 = ax * ay;
  for (int j = 0; j < n; ++j) {
    const uint8_t* r0 = img.ptr<uint8_t>(iy + j) + ix;
    const uint8_t* r1 = r0 + img.step[0];
    float* o = out + j * n;
    for (int i = 0; i < n; ++i) o[i] = w00 * r0[i] + w10 * r0[i + 1] + w01 * r1[i] + w11 * r1[i + 1];
  }
  return true;
}

float ImagePyramid::sample(int level, double x, double y) const {
  const cv::Mat& img = levels_[level];
  const int ix = std::min(static_cast<int>(x), img.cols - 2), iy = std::min(static_cast<int>(y), img.rows - 2);
  const float ax = static_cast<float>(x - ix), ay = static_cast<float>(y - iy);
  const uint8_t* r0 = img.ptr<uint8_t>(iy) + ix;
  const uint8_t* r1 = r0 + img.step[0];
  return (1 - ax) * (1 - ay) * r0[0] + ax * (1 - ay) * r0[1] + (1 - ax) * ay * r1[0] + ax * ay * r1[1];
}

}  // namespace livo::vio
