#include "livo/sim/depth_effects.hpp"

#include <algorithm>
#include <cmath>

namespace livo::sim {

namespace {

/// Pixels with depth that differ from a 4-neighbour by more than `jump` (relative) or border one
/// without depth.
std::vector<uint8_t> discontinuities(const std::vector<float>& z, int width, int height, double jump) {
  std::vector<uint8_t> edge(z.size(), 0);
  auto differs = [&](size_t a, size_t b) {
    if (z[a] <= 0.0f) return false;
    if (z[b] <= 0.0f) return true;
    return std::abs(z[a] - z[b]) > jump * std::min(z[a], z[b]);
  };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t k = static_cast<size_t>(y) * width + x;
      edge[k] = (x > 0 && differs(k, k - 1)) || (x + 1 < width && differs(k, k + 1)) ||
                (y > 0 && differs(k, k - width)) || (y + 1 < height && differs(k, k + width));
    }
  }
  return edge;
}

/// The mask grown by `r` pixels (a (2r + 1)-square), rows then columns.
void dilate(std::vector<uint8_t>* mask, int width, int height, int r) {
  if (r <= 0) return;
  std::vector<uint8_t> rows(mask->size(), 0);
  for (int y = 0; y < height; ++y) {
    const uint8_t* in = &(*mask)[static_cast<size_t>(y) * width];
    uint8_t* out = &rows[static_cast<size_t>(y) * width];
    for (int x = 0; x < width; ++x)
      if (in[x])
        for (int i = std::max(0, x - r); i <= std::min(width - 1, x + r); ++i) out[i] = 1;
  }
  std::fill(mask->begin(), mask->end(), 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (!rows[static_cast<size_t>(y) * width + x]) continue;
      for (int j = std::max(0, y - r); j <= std::min(height - 1, y + r); ++j)
        (*mask)[static_cast<size_t>(j) * width + x] = 1;
    }
  }
}

}  // namespace

std::vector<uint16_t> measureDepth(const std::vector<float>& z_exact, int width, int height, const DepthEffects& e,
                                   Random rng) {
  const size_t n = static_cast<size_t>(width) * height;
  // holes: a band at each discontinuity (the pixels across a jump and edge_hole_px - 1 more)
  std::vector<uint8_t> hole(n, 0);
  if (e.edge_hole_px > 0) {
    hole = discontinuities(z_exact, width, height, e.edge_jump);
    dilate(&hole, width, height, e.edge_hole_px - 1);
  }
  // blobs: discs at uniform centres (a Boolean model: the share covered is 1 - exp(-density x mean
  // area), so this many give hole_fraction, borders aside)
  if (e.hole_fraction > 0.0) {
    const double mean_area = M_PI * e.hole_radius_px * e.hole_radius_px * (13.0 / 12.0);  // E[r^2] of U[0.5, 1.5] r
    const int blobs =
        static_cast<int>(std::lround(-std::log(1.0 - e.hole_fraction) * static_cast<double>(n) / mean_area));
    for (int b = 0; b < blobs; ++b) {
      const double cx = rng.uniform(0.0, width), cy = rng.uniform(0.0, height);
      const double r = e.hole_radius_px * rng.uniform(0.5, 1.5);
      const int y0 = std::max(0, static_cast<int>(std::floor(cy - r))),
                y1 = std::min(height - 1, static_cast<int>(std::ceil(cy + r)));
      const int x0 = std::max(0, static_cast<int>(std::floor(cx - r))),
                x1 = std::min(width - 1, static_cast<int>(std::ceil(cx + r)));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x)
          if ((x + 0.5 - cx) * (x + 0.5 - cx) + (y + 0.5 - cy) * (y + 0.5 - cy) <= r * r)
            hole[static_cast<size_t>(y) * width + x] = 1;
    }
  }
  std::vector<uint16_t> mm(n, 0);
  for (size_t k = 0; k < n; ++k) {
    const double z = z_exact[k];
    if (hole[k] || !(z >= e.min_range && z <= e.max_range)) continue;
    const double measured = z + e.sigmaAt(z) * rng.normal();
    mm[k] = static_cast<uint16_t>(std::clamp(std::lround(measured * 1e3), 0L, 65535L));
  }
  return mm;
}

}  // namespace livo::sim
