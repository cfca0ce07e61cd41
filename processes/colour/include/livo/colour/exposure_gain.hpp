// Exposure normalisation: the gain of one image relative to the map, as the median of the
// luminance ratios between its (already exposure-time-normalised) samples and the map's colours.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace livo::colour {

inline float luminance(const Eigen::Vector3f& c) { return 0.299f * c[0] + 0.587f * c[1] + 0.114f * c[2]; }

struct GainEstimate {
  double gain = 1.0;
  int pairs = 0;
  bool valid = false;
};

/// `observed[i]` and `mapped[i]` are colours of the same point; pairs darker than `min_luminance`
/// or saturated (>= 250) are ignored. Valid if at least `min_pairs` remain and the median ratio
/// lies in [gain_min, gain_max].
GainEstimate estimateGain(const std::vector<Eigen::Vector3f>& observed, const std::vector<Eigen::Vector3f>& mapped,
                          int min_pairs, double gain_min, double gain_max, float min_luminance = 10.0f);

}  // namespace livo::colour
