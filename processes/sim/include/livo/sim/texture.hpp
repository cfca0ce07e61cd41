// Procedural surface textures (gradient noise, bricks, checker, stripes, uniform), baked once into
// a tileable mip-mapped RGB tile and sampled trilinearly with the pixel's footprint on the surface,
// so distant or grazing surfaces are filtered the way a real lens and sensor would.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace livo::sim {

enum class TexturePattern { kUniform, kNoise, kBricks, kChecker, kStripes };

/// Parses "uniform", "noise", "bricks", "checker" or "stripes"; false if unknown.
bool parseTexturePattern(const std::string& name, TexturePattern* pattern);

struct TextureOptions {
  TexturePattern pattern = TexturePattern::kNoise;
  Eigen::Vector3d color_a{0.7, 0.7, 0.7};  // linear RGB in [0, 1]: base / brick / first square
  Eigen::Vector3d color_b{0.3, 0.3, 0.3};  // second colour / mortar
  double scale = 0.5;                      // m: noise feature size, brick length, checker square, stripe width
  double brick_height = 0.1;               // m (bricks)
  double mortar = 0.012;                   // m (bricks)
  int octaves = 4;                         // noise
  double grain = 0.15;                     // relative amplitude of fine noise over any pattern (0 = none)
  double variation = 0.15;                 // relative brightness variation between bricks, squares, stripes
  uint64_t seed = 1;
};

class Texture {
 public:
  explicit Texture(const TextureOptions& options);

  /// Colour at surface coordinates (u, v) in metres, averaged over a footprint of `footprint` m.
  Eigen::Vector3f sample(double u, double v, double footprint) const;
  /// Luminance (0.299 R + 0.587 G + 0.114 B) of the same, from a single-channel copy (faster).
  float sampleLuminance(double u, double v, double footprint) const;

  double periodU() const { return period_u_; }
  double periodV() const { return period_v_; }

 private:
  Eigen::Vector3d bakeTexel(double u, double v, double noise_norm_lo, double noise_norm_hi) const;
  template <int C>
  void bilinear(const std::vector<float>& level, int n, double x, double y, float* out) const;
  double mipLevel(double footprint) const;

  TextureOptions options_;
  double period_u_ = 1.0, period_v_ = 1.0;
  int size_ = 1;                               // texels per side at level 0
  std::vector<std::vector<float>> levels_;     // RGB, level l has (size_ >> l)^2 texels
  std::vector<std::vector<float>> luminance_;  // the same as luminance
};

}  // namespace livo::sim
