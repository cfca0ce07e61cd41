// Reproducible random numbers: one independent stream per (seed, stream, index), so a message's
// noise depends only on which message it is, never on which thread made it or in what order.
#pragma once

#include <cmath>
#include <cstdint>

#include <Eigen/Core>

namespace livo::sim {

/// SplitMix64 step: a good 64-bit mixer, used to seed and as a hash.
inline uint64_t mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// Stable 64-bit hash of a string (FNV-1a, then mixed).
inline uint64_t hashString(const char* s) {
  uint64_t h = 1469598103934665603ULL;
  for (; *s; ++s) h = (h ^ static_cast<unsigned char>(*s)) * 1099511628211ULL;
  return mix64(h);
}

/// xoshiro256** seeded from (seed, stream, index); normal() by the polar method.
class Random {
 public:
  Random(uint64_t seed, uint64_t stream, uint64_t index = 0) {
    uint64_t x = mix64(seed) ^ mix64(stream + 0x632be59bd9b4e019ULL) ^ mix64(index * 0x8cb92ba72f3d8dd7ULL + 1);
    for (auto& w : s_) w = x = mix64(x);
  }

  uint64_t next() {
    const uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

  /// A hash of the current state, without advancing it: seeds per-ray streams (e.g. a LiDAR beam's
  /// vegetation depth) without changing the draws that follow.
  uint64_t key() const { return mix64(s_[0] ^ rotl(s_[1], 17) ^ rotl(s_[2], 31) ^ rotl(s_[3], 47)); }

  /// Uniform in [0, 1).
  double uniform() { return static_cast<double>(next() >> 11) * (1.0 / 9007199254740992.0); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

  /// Standard normal.
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u, v, s;
    do {
      u = 2.0 * uniform() - 1.0;
      v = 2.0 * uniform() - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double k = std::sqrt(-2.0 * std::log(s) / s);
    spare_ = v * k;
    has_spare_ = true;
    return u * k;
  }
  Eigen::Vector3d normal3() {
    const double a = normal(), b = normal(), c = normal();
    return Eigen::Vector3d(a, b, c);
  }

 private:
  static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  uint64_t s_[4];
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace livo::sim
