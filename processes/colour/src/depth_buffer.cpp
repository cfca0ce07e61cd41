#include "livo/colour/depth_buffer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace livo::colour {

DepthBuffer::DepthBuffer(int width, int height, double focal_px, const DepthBufferOptions& options)
    : options_(options),
      cols_((width + std::max(1, options.cell_px) - 1) / std::max(1, options.cell_px)),
      rows_((height + std::max(1, options.cell_px) - 1) / std::max(1, options.cell_px)),
      focal_(focal_px) {
  options_.cell_px = std::max(1, options_.cell_px);
  depth_.assign(static_cast<size_t>(cols_) * rows_, std::numeric_limits<float>::infinity());
  nearest_centred_.assign(depth_.size(), kNoCentre);
}

void DepthBuffer::clear() { std::fill(depth_.begin(), depth_.end(), std::numeric_limits<float>::infinity()); }

int DepthBuffer::cellIndex(const Eigen::Vector2d& pixel, int* cx, int* cy) const {
  *cx = std::clamp(static_cast<int>(pixel.x() + 0.5) / options_.cell_px, 0, cols_ - 1);
  *cy = std::clamp(static_cast<int>(pixel.y() + 0.5) / options_.cell_px, 0, rows_ - 1);
  return *cy * cols_ + *cx;
}

void DepthBuffer::splat(const Eigen::Vector2d& pixel, double z) {
  int cx, cy;
  cellIndex(pixel, &cx, &cy);
  splatCell(cx, cy, z);
}

void DepthBuffer::splatCell(int cx, int cy, double z) {
  const double radius_px = focal_ * options_.occluder_radius / std::max(z, 1e-3);
  const int r = std::min(options_.max_splat_cells, static_cast<int>(radius_px / options_.cell_px));
  const float zf = static_cast<float>(z);
  for (int y = std::max(0, cy - r); y <= std::min(rows_ - 1, cy + r); ++y) {
    float* row = &depth_[static_cast<size_t>(y) * cols_];
    for (int x = std::max(0, cx - r); x <= std::min(cols_ - 1, cx + r); ++x) row[x] = std::min(row[x], zf);
  }
}

float DepthBuffer::nearest(const Eigen::Vector2d& pixel) const {
  int cx, cy;
  return depth_[cellIndex(pixel, &cx, &cy)];
}

bool DepthBuffer::visible(const Eigen::Vector2d& pixel, double z) const {
  return z <= nearest(pixel) + options_.tolerance + options_.tolerance_rel * z;
}

}  // namespace livo::colour
