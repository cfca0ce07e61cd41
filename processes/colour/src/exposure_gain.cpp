#include "livo/colour/exposure_gain.hpp"

#include <algorithm>

namespace livo::colour {

GainEstimate estimateGain(const std::vector<Eigen::Vector3f>& observed, const std::vector<Eigen::Vector3f>& mapped,
                          int min_pairs, double gain_min, double gain_max, float min_luminance) {
  std::vector<float> ratios;
  ratios.reserve(observed.size());
  for (size_t i = 0; i < observed.size() && i < mapped.size(); ++i) {
    const float lo = luminance(observed[i]), lm = luminance(mapped[i]);
    if (lo < min_luminance || lm < min_luminance || observed[i].maxCoeff() >= 250.0f) continue;
    ratios.push_back(lo / lm);
  }
  GainEstimate g;
  g.pairs = static_cast<int>(ratios.size());
  if (g.pairs < std::max(1, min_pairs)) return g;
  auto mid = ratios.begin() + ratios.size() / 2;
  std::nth_element(ratios.begin(), mid, ratios.end());
  g.gain = *mid;
  g.valid = g.gain >= gain_min && g.gain <= gain_max;
  if (!g.valid) g.gain = 1.0;
  return g;
}

}  // namespace livo::colour
