#include "livo/sim/noise.hpp"

#include <cmath>

#include "livo/sim/random.hpp"

namespace livo::sim {

namespace {
inline double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

inline int wrap(int64_t i, int period) {
  const int64_t m = i % period;
  return static_cast<int>(m < 0 ? m + period : m);
}

// 32 unit gradient directions, evenly spaced in angle.
struct GradientTable {
  double x[32], y[32];
  GradientTable() {
    for (int i = 0; i < 32; ++i)
      x[i] = std::cos(2.0 * M_PI * (i + 0.5) / 32.0), y[i] = std::sin(2.0 * M_PI * (i + 0.5) / 32.0);
  }
};
const GradientTable kGradients;

inline double gradientDot(int ix, int iy, double dx, double dy, uint64_t seed) {
  const uint64_t h =
      mix64(seed ^ ((static_cast<uint64_t>(static_cast<uint32_t>(ix)) << 32) | static_cast<uint32_t>(iy)));
  const int k = static_cast<int>(h >> 59);
  return kGradients.x[k] * dx + kGradients.y[k] * dy;
}
}  // namespace

double gradientNoise(double x, double y, int period, uint64_t seed) {
  const double fx = std::floor(x), fy = std::floor(y);
  const int64_t ix = static_cast<int64_t>(fx), iy = static_cast<int64_t>(fy);
  const double dx = x - fx, dy = y - fy;
  const int x0 = wrap(ix, period), x1 = wrap(ix + 1, period);
  const int y0 = wrap(iy, period), y1 = wrap(iy + 1, period);
  const double n00 = gradientDot(x0, y0, dx, dy, seed);
  const double n10 = gradientDot(x1, y0, dx - 1.0, dy, seed);
  const double n01 = gradientDot(x0, y1, dx, dy - 1.0, seed);
  const double n11 = gradientDot(x1, y1, dx - 1.0, dy - 1.0, seed);
  const double u = fade(dx), v = fade(dy);
  const double a = n00 + u * (n10 - n00);
  const double b = n01 + u * (n11 - n01);
  return 1.41421356 * (a + v * (b - a));
}

double fractalNoise(double x, double y, int octaves, int period, uint64_t seed) {
  double sum = 0.0, amplitude = 1.0, norm = 0.0, scale = 1.0;
  for (int o = 0; o < octaves; ++o) {
    sum += amplitude * gradientNoise(x * scale, y * scale, period * static_cast<int>(scale), seed + 977 * o);
    norm += amplitude;
    amplitude *= 0.5;
    scale *= 2.0;
  }
  return sum / norm;
}

}  // namespace livo::sim
