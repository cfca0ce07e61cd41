#include "livo/vio/image_pyramid.hpp"

#include <algorithm>
#include <cmath>

#include "livo/vio/patch.hpp"

namespace livo::vio {

namespace {

// One output row of the 2x2 average: `w` pixels from source rows r0, r1. Blocks of a fixed 16
// pixels so that -O2's cheap vectoriser takes them (exact integer arithmetic, any lane order);
// the remainder pixel by pixel.
void averageRow(const uint8_t* __restrict r0, const uint8_t* __restrict r1, uint8_t* __restrict d, int w) {
  constexpr int kBlock = 16;
  int x = 0;
  for (; x + kBlock <= w; x += kBlock) {
    const uint8_t* a = r0 + 2 * x;
    const uint8_t* b = r1 + 2 * x;
    uint8_t* o = d + x;
    for (int k = 0; k < kBlock; ++k)
      o[k] = static_cast<uint8_t>((a[2 * k] + a[2 * k + 1] + b[2 * k] + b[2 * k + 1] + 2) >> 2);
  }
  for (; x < w; ++x) d[x] = static_cast<uint8_t>((r0[2 * x] + r0[2 * x + 1] + r1[2 * x] + r1[2 * x + 1] + 2) >> 2);
}

// n bilinear samples along a row with shared weights.
inline void bilinearRow(const uint8_t* r0, const uint8_t* r1, float w00, float w10, float w01, float w11, float* o,
                        int n) {
  for (int i = 0; i < n; ++i) o[i] = w00 * r0[i] + w10 * r0[i + 1] + w01 * r1[i] + w11 * r1[i + 1];
}

// The N x N grid at (ix, iy): the (N+1)^2 pixels it reads converted to float once (each is a tap of
// up to four samples), then the rows unrolled so that the compiler's straight-line (SLP)
// vectoriser evaluates them four at a time: per lane the same expression,
// ((w00 a + w10 b) + w01 c) + w11 d, on the same values, so bit for bit the scalar result.
template <int N>
void sampleRows(const cv::Mat& img, int ix, int iy, float w00, float w10, float w01, float w11, float* __restrict out) {
  constexpr int kStride = (N + 1 + 3) / 4 * 4;
  float px[(N + 1) * kStride];
  for (int j = 0; j <= N; ++j) {
    const uint8_t* r = img.ptr<uint8_t>(iy + j) + ix;
    float* f = px + j * kStride;
#pragma GCC unroll 16
    for (int i = 0; i <= N; ++i) f[i] = r[i];
  }
  for (int j = 0; j < N; ++j) {
    const float* r0 = px + j * kStride;
    const float* r1 = r0 + kStride;
    float* o = out + j * N;
#pragma GCC unroll 16
    for (int i = 0; i < N; ++i) o[i] = w00 * r0[i] + w10 * r0[i + 1] + w01 * r1[i] + w11 * r1[i + 1];
  }
}

}  // namespace

void ImagePyramid::build(const cv::Mat& grey, int levels) {
  levels_.resize(static_cast<size_t>(std::max(1, levels)));
  levels_[0] = grey;
  for (size_t l = 1; l < levels_.size(); ++l) {
    const cv::Mat& src = levels_[l - 1];
    const int w = src.cols / 2, h = src.rows / 2;
    cv::Mat& dst = levels_[l];
    dst.create(h, w, CV_8UC1);  // keeps the last image's buffer (same size)
    for (int y = 0; y < h; ++y)
      averageRow(src.ptr<uint8_t>(2 * y), src.ptr<uint8_t>(2 * y + 1), dst.ptr<uint8_t>(y), w);
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
  // the patch sizes the update samples get the vectorised rows
  if (n == kWindow) {
    sampleRows<kWindow>(img, ix, iy, w00, w10, w01, w11, out);
  } else if (n == kStored) {
    sampleRows<kStored>(img, ix, iy, w00, w10, w01, w11, out);
  } else {
    for (int j = 0; j < n; ++j) {
      const uint8_t* r0 = img.ptr<uint8_t>(iy + j) + ix;
      bilinearRow(r0, r0 + img.step[0], w00, w10, w01, w11, out + j * n, n);
    }
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
