#include "livo/sim/auto_exposure.hpp"

#include <algorithm>
#include <cmath>

namespace livo::sim {

AutoExposure::AutoExposure(const AutoExposureOptions& options, double initial_exposure) : options_(options) {
  setting_.exposure = std::clamp(initial_exposure, options_.min_exposure, options_.max_exposure);
  setting_.gain = options_.min_gain;
}

void AutoExposure::update(double measured_mean) {
  // a black image says only "much brighter": meter it as half a grey level
  const double ratio = options_.target_mean / std::max(measured_mean, 0.5);
  const double total = setting_.exposure * setting_.gain * std::pow(ratio, options_.rate);
  setting_.exposure = std::clamp(total / options_.min_gain, options_.min_exposure, options_.max_exposure);
  setting_.gain = std::clamp(total / setting_.exposure, options_.min_gain, options_.max_gain);
}

double AutoExposure::meanLevel(const std::vector<uint8_t>& data) {
  if (data.empty()) return 0.0;
  uint64_t sum = 0;
  for (uint8_t v : data) sum += v;
  return static_cast<double>(sum) / static_cast<double>(data.size());
}

}  // namespace livo::sim
