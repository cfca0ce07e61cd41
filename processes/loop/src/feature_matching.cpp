#include "livo/loop/feature_matching.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace livo::loop {

static_assert(kFpfhSize == 33, "the distance below takes bins 0-31 by SAD and bin 32 by hand");

bool Descriptor::isZero() const {
  return std::all_of(bins.begin(), bins.end(), [](uint8_t b) { return b == 0; });
}

Descriptor quantise(const Fpfh& feature) {
  Descriptor d;
  for (int k = 0; k < kFpfhSize; ++k) d.bins[k] = static_cast<uint8_t>(std::clamp(std::lround(feature[k]), 0L, 255L));
  return d;
}

Descriptors quantise(const Features& features) {
  Descriptors out;
  out.reserve(features.size());
  for (const Fpfh& f : features) out.push_back(quantise(f));
  return out;
}

namespace {
#if defined(__SSE2__)
// Bins 0-31 by two SSE2 sums of absolute differences, bin 32 (the last of the 33) by hand: the
// SAD unit is the bottleneck, so this is a third faster than a third SAD over bytes 32-47.
struct Loaded {
  __m128i a, b;
  int last;
  explicit Loaded(const Descriptor& d)
      : a(_mm_load_si128(reinterpret_cast<const __m128i*>(d.bins.data()))),
        b(_mm_load_si128(reinterpret_cast<const __m128i*>(d.bins.data() + 16))),
        last(d.bins[32]) {}
};
inline int distance(const Loaded& x, const Descriptor& d) {
  const __m128i* p = reinterpret_cast<const __m128i*>(d.bins.data());
  const __m128i s = _mm_add_epi64(_mm_sad_epu8(x.a, _mm_load_si128(p)), _mm_sad_epu8(x.b, _mm_load_si128(p + 1)));
  return _mm_cvtsi128_si32(s) + _mm_cvtsi128_si32(_mm_unpackhi_epi64(s, s)) + std::abs(x.last - int(d.bins[32]));
}
#else
using Loaded = Descriptor;
inline int distance(const Descriptor& x, const Descriptor& d) {
  int s = 0;
  for (size_t k = 0; k < d.bins.size(); ++k) s += std::abs(int(x.bins[k]) - int(d.bins[k]));
  return s;
}
#endif

std::vector<int> nonZero(const Descriptors& d) {
  std::vector<int> out;
  for (size_t i = 0; i < d.size(); ++i)
    if (!d[i].isZero()) out.push_back(static_cast<int>(i));
  return out;
}
}  // namespace

int descriptorDistance(const Descriptor& a, const Descriptor& b) { return distance(Loaded(a), b); }

Correspondences matchDescriptors(const Descriptors& source, const Descriptors& target,
                                 const FeatureMatchingOptions& options) {
  const std::vector<int> si = nonZero(source), ti = nonZero(target);
  if (si.empty() || ti.empty()) return {};
  std::vector<Descriptor> tv;
  tv.reserve(ti.size());
  for (int j : ti) tv.push_back(target[j]);
  // One pass over all pairs: each source's nearest target and each target's nearest source.
  std::vector<int> row_best(si.size(), -1), row_dist(si.size(), INT_MAX);
  std::vector<int> col_best(tv.size(), -1), col_dist(tv.size(), INT_MAX);
  for (size_t a = 0; a < si.size(); ++a) {
    const Loaded s(source[si[a]]);
    int best = -1, best_d = INT_MAX;
    for (size_t b = 0; b < tv.size(); ++b) {
      const int d = distance(s, tv[b]);
      if (d < best_d) {
        best_d = d;
        best = static_cast<int>(b);
      }
      if (d < col_dist[b]) {
        col_dist[b] = d;
        col_best[b] = static_cast<int>(a);
      }
    }
    row_best[a] = best;
    row_dist[a] = best_d;
  }
  std::vector<std::pair<int, Correspondence>> kept;
  for (size_t a = 0; a < si.size(); ++a) {
    const int b = row_best[a];
    if (options.mutual && col_best[b] != static_cast<int>(a)) continue;
    kept.push_back({row_dist[a], {si[a], ti[b]}});
  }
  if (options.max_correspondences > 0 && kept.size() > static_cast<size_t>(options.max_correspondences)) {
    std::stable_sort(kept.begin(), kept.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    kept.resize(options.max_correspondences);
  }
  Correspondences out;
  out.reserve(kept.size());
  for (const auto& k : kept) out.push_back(k.second);
  return out;
}

}  // namespace livo::loop
