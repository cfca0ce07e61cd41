#include "livo/sim/texture.hpp"

#include <algorithm>
#include <cmath>

#include "livo/sim/noise.hpp"
#include "livo/sim/random.hpp"

namespace livo::sim {

namespace {
constexpr int kTileTexels = 256;
constexpr int kNoiseCells = 8;   // lattice cells of the first noise octave per tile
constexpr int kGrainCells = 64;  // lattice cells of the grain per tile

double cellVariation(uint64_t seed, int64_t a, int64_t b, double amount) {
  Random r(seed, static_cast<uint64_t>(a) * 7919 + 13, static_cast<uint64_t>(b));
  return 1.0 + amount * (2.0 * r.uniform() - 1.0);
}
double wrapUnit(double x) { return x - std::floor(x); }

/// log2 to within 0.09, enough to pick a mip level.
double roughLog2(double x) {
  int e;
  const double m = std::frexp(x, &e);  // x = m 2^e, m in [0.5, 1)
  return e - 2.0 + 2.0 * m;
}
}  // namespace

bool parseTexturePattern(const std::string& name, TexturePattern* p) {
  if (name == "uniform")
    *p = TexturePattern::kUniform;
  else if (name == "noise")
    *p = TexturePattern::kNoise;
  else if (name == "bricks")
    *p = TexturePattern::kBricks;
  else if (name == "checker")
    *p = TexturePattern::kChecker;
  else if (name == "stripes")
    *p = TexturePattern::kStripes;
  else
    return false;
  return true;
}

Texture::Texture(const TextureOptions& o) : options_(o) {
  switch (o.pattern) {
    case TexturePattern::kUniform: period_u_ = period_v_ = std::max(o.scale, 1e-3) * 8.0; break;
    case TexturePattern::kNoise: period_u_ = period_v_ = o.scale * kNoiseCells; break;
    case TexturePattern::kBricks: period_u_ = 4.0 * o.scale, period_v_ = 8.0 * o.brick_height; break;
    case TexturePattern::kChecker: period_u_ = period_v_ = 8.0 * o.scale; break;
    case TexturePattern::kStripes: period_u_ = period_v_ = 16.0 * o.scale; break;
  }
  size_ = (o.pattern == TexturePattern::kUniform && o.grain <= 0.0) ? 1 : kTileTexels;

  // level 0
  std::vector<double> raw(static_cast<size_t>(size_) * size_ * 3);
  double lo = 0.0, hi = 1.0;
  if (o.pattern == TexturePattern::kNoise) {  // normalise the noise to the full colour range
    lo = 1e300, hi = -1e300;
    for (int j = 0; j < size_; ++j)
      for (int i = 0; i < size_; ++i) {
        const double n = fractalNoise((i + 0.5) * kNoiseCells / size_, (j + 0.5) * kNoiseCells / size_, o.octaves,
                                      kNoiseCells, o.seed);
        lo = std::min(lo, n), hi = std::max(hi, n);
      }
  }
  levels_.emplace_back(static_cast<size_t>(size_) * size_ * 3);
  for (int j = 0; j < size_; ++j) {
    for (int i = 0; i < size_; ++i) {
      const double u = (i + 0.5) / size_ * period_u_, v = (j + 0.5) / size_ * period_v_;
      const Eigen::Vector3d c = bakeTexel(u, v, lo, hi);
      float* px = &levels_[0][(static_cast<size_t>(j) * size_ + i) * 3];
      for (int k = 0; k < 3; ++k) px[k] = static_cast<float>(std::clamp(c[k], 0.0, 1.0));
    }
  }
  // mip levels by 2x2 box filtering
  for (int n = size_ / 2; n >= 1; n /= 2) {
    const std::vector<float>& prev = levels_.back();
    std::vector<float> next(static_cast<size_t>(n) * n * 3);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
          auto at = [&](int x, int y) { return prev[(static_cast<size_t>(y) * 2 * n + x) * 3 + k]; };
          next[(static_cast<size_t>(j) * n + i) * 3 + k] =
              0.25f * (at(2 * i, 2 * j) + at(2 * i + 1, 2 * j) + at(2 * i, 2 * j + 1) + at(2 * i + 1, 2 * j + 1));
        }
    levels_.push_back(std::move(next));
  }
  for (const auto& level : levels_) {
    std::vector<float> y(level.size() / 3);
    for (size_t i = 0; i < y.size(); ++i)
      y[i] = 0.299f * level[3 * i] + 0.587f * level[3 * i + 1] + 0.114f * level[3 * i + 2];
    luminance_.push_back(std::move(y));
  }
}

Eigen::Vector3d Texture::bakeTexel(double u, double v, double lo, double hi) const {
  const TextureOptions& o = options_;
  Eigen::Vector3d c = o.color_a;
  switch (o.pattern) {
    case TexturePattern::kUniform: break;
    case TexturePattern::kNoise: {
      const double n = fractalNoise(u / o.scale, v / o.scale, o.octaves, kNoiseCells, o.seed);
      const double a = (n - lo) / std::max(hi - lo, 1e-12);
      c = (1.0 - a) * o.color_b + a * o.color_a;
      break;
    }
    case TexturePattern::kBricks: {
      const int64_t row = static_cast<int64_t>(std::floor(v / o.brick_height));
      const double shift = (row % 2) ? 0.5 * o.scale : 0.0;
      const double uu = u + shift;
      const int64_t col = static_cast<int64_t>(std::floor(uu / o.scale));
      const double du = uu - col * o.scale, dv = v - row * o.brick_height;
      const double m = 0.5 * o.mortar;
      if (du < m || du > o.scale - m || dv < m || dv > o.brick_height - m) {
        c = o.color_b;
      } else {
        // bricks repeat every 4 columns and 8 rows: wrap the ids for a tileable variation
        c = o.color_a * cellVariation(o.seed, ((col % 4) + 4) % 4, ((row % 8) + 8) % 8, o.variation);
      }
      break;
    }
    case TexturePattern::kChecker: {
      const int64_t a = static_cast<int64_t>(std::floor(u / o.scale)),
                    b = static_cast<int64_t>(std::floor(v / o.scale));
      c = (((a + b) % 2 + 2) % 2 == 0 ? o.color_a : o.color_b) * cellVariation(o.seed, a & 7, b & 7, o.variation);
      break;
    }
    case TexturePattern::kStripes: {
      const int64_t a = static_cast<int64_t>(std::floor(u / o.scale));
      c = ((a % 2 + 2) % 2 == 0 ? o.color_a : o.color_b) * cellVariation(o.seed, a & 15, 0, o.variation);
      break;
    }
  }
  if (o.grain > 0.0) {
    const double g =
        fractalNoise(u / period_u_ * kGrainCells, v / period_v_ * kGrainCells, 2, kGrainCells, o.seed + 101);
    c *= 1.0 + o.grain * g;
  }
  return c;
}

template <int C>
void Texture::bilinear(const std::vector<float>& t, int n, double x, double y, float* out) const {
  const double fx = std::floor(x), fy = std::floor(y);
  const float ax = static_cast<float>(x - fx), ay = static_cast<float>(y - fy);
  const int64_t mask = n - 1;  // n is a power of two; & wraps negative indices too
  const int x0 = static_cast<int>(static_cast<int64_t>(fx) & mask),
            y0 = static_cast<int>(static_cast<int64_t>(fy) & mask);
  const int x1 = static_cast<int>((x0 + 1) & mask), y1 = static_cast<int>((y0 + 1) & mask);
  const float* p00 = &t[(static_cast<size_t>(y0) * n + x0) * C];
  const float* p10 = &t[(static_cast<size_t>(y0) * n + x1) * C];
  const float* p01 = &t[(static_cast<size_t>(y1) * n + x0) * C];
  const float* p11 = &t[(static_cast<size_t>(y1) * n + x1) * C];
  for (int k = 0; k < C; ++k) {
    const float a = p00[k] + ax * (p10[k] - p00[k]);
    const float b = p01[k] + ax * (p11[k] - p01[k]);
    out[k] = a + ay * (b - a);
  }
}

double Texture::mipLevel(double footprint) const {
  const double texel = std::max(period_u_, period_v_) / size_;
  return std::clamp(roughLog2(std::max(footprint, 1e-12) / texel), 0.0, static_cast<double>(levels_.size() - 1));
}

Eigen::Vector3f Texture::sample(double u, double v, double footprint) const {
  if (size_ == 1) return Eigen::Map<const Eigen::Vector3f>(levels_[0].data());
  const double lod = mipLevel(footprint);
  const int l0 = static_cast<int>(lod);
  const int l1 = std::min(l0 + 1, static_cast<int>(levels_.size()) - 1);
  const float w = static_cast<float>(lod - l0);
  const double fu = wrapUnit(u / period_u_), fv = wrapUnit(v / period_v_);
  Eigen::Vector3f a, b;
  const int n0 = size_ >> l0, n1 = size_ >> l1;
  bilinear<3>(levels_[l0], n0, fu * n0 - 0.5, fv * n0 - 0.5, a.data());
  if (w <= 0.0f || l1 == l0) return a;
  bilinear<3>(levels_[l1], n1, fu * n1 - 0.5, fv * n1 - 0.5, b.data());
  return a + w * (b - a);
}

float Texture::sampleLuminance(double u, double v, double footprint) const {
  if (size_ == 1) return luminance_[0][0];
  const double lod = mipLevel(footprint);
  const int l0 = static_cast<int>(lod);
  const int l1 = std::min(l0 + 1, static_cast<int>(levels_.size()) - 1);
  const float w = static_cast<float>(lod - l0);
  const double fu = wrapUnit(u / period_u_), fv = wrapUnit(v / period_v_);
  float a, b;
  const int n0 = size_ >> l0, n1 = size_ >> l1;
  bilinear<1>(luminance_[l0], n0, fu * n0 - 0.5, fv * n0 - 0.5, &a);
  if (w <= 0.0f || l1 == l0) return a;
  bilinear<1>(luminance_[l1], n1, fu * n1 - 0.5, fv * n1 - 0.5, &b);
  return a + w * (b - a);
}

}  // namespace livo::sim
