#include "livo/sim/lidar_effects.hpp"

#include <algorithm>
#include <cmath>

namespace livo::sim {

namespace {
// Phi^-1(kDetectionAtRatedRange): the threshold sits this many softness units below the rated power
constexpr double kZ90 = 1.2815515655446004;

double standardNormalCdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

/// One echo from the hits [first, end) of a group (sorted by range).
Echo mergedEcho(const std::vector<SubRayHit>& hits, size_t first, size_t end) {
  const SubRayHit& nearest = hits[first];
  Echo echo;
  if (end - first == 1) {  // a single surface: its own reflectivity and incidence
    echo.range = nearest.range;
    echo.reflectivity = nearest.reflectivity;
    echo.cos_incidence = nearest.cos_incidence;
    echo.share = nearest.weight;
    return echo;
  }
  double power = 0.0, weighted_range = 0.0, share = 0.0;
  for (size_t i = first; i < end; ++i) {
    power += hits[i].power();
    weighted_range += hits[i].power() * hits[i].range;
    share += hits[i].weight;
  }
  echo.range = power > 0.0 ? weighted_range / power : nearest.range;
  echo.reflectivity = power * echo.range * echo.range / share;
  echo.share = share;
  return echo;
}
}  // namespace

double rangeNoiseStd(const LidarEffects& e, double base_std, double range, double apparent_reflectivity) {
  if (e.range_noise_per_m <= 0.0) return base_std;
  const double apparent = std::max(apparent_reflectivity, kMinApparentReflectivity);
  const double growing =
      e.range_noise_per_m * range * std::pow(kNoiseReferenceReflectivity / apparent, e.noise_reflectivity_exponent);
  return std::hypot(base_std, growing);
}

double detectionProbability(const LidarEffects& e, double range, double apparent_reflectivity) {
  if (!e.detection()) return 1.0;
  if (apparent_reflectivity <= 0.0) return 0.0;
  // ln of the received power relative to a 10 % target at normal incidence at the rated range
  const double log_power = std::log(apparent_reflectivity / 0.1) + 2.0 * std::log(e.max_range_at_10pct / range);
  return standardNormalCdf(log_power / e.detection_softness + kZ90);
}

std::vector<SubRay> footprintSubRays(const LidarEffects& e) {
  const double half_h = 0.5e-3 * e.beam_divergence_mrad[0], half_v = 0.5e-3 * e.beam_divergence_mrad[1];
  std::vector<SubRay> rays{{0.0, 0.0, 0.25}};
  for (int k = 0; k < 6; ++k) {
    const double a = k * M_PI / 3.0;
    rays.push_back({half_h * std::cos(a), half_v * std::sin(a), 0.125});
  }
  return rays;
}

Echo strongestEcho(std::vector<SubRayHit>* hits, double separation) {
  std::sort(hits->begin(), hits->end(), [](const SubRayHit& a, const SubRayHit& b) { return a.range < b.range; });
  Echo best;
  double best_power = -1.0;
  for (size_t first = 0, end = 0; first < hits->size(); first = end) {
    end = first + 1;
    while (end < hits->size() && (*hits)[end].range - (*hits)[first].range < separation) ++end;
    const Echo echo = mergedEcho(*hits, first, end);
    const double power = echo.apparentReflectivity() / (echo.range * echo.range);
    if (power > best_power) best = echo, best_power = power;  // ties: the nearer echo
  }
  return best;
}

}  // namespace livo::sim
