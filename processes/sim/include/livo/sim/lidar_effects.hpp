// What a real time-of-flight LiDAR receiver does to a return, beyond the nominal geometry:
// range noise that grows with range and with falling return power, a detection probability that
// falls with range and rises with reflectivity, and a beam of finite divergence whose footprint
// can straddle a depth edge (mixed pixels, strongest return). All of it off by default.
//
// The received power of a Lambertian target filling the beam goes as
//   p = reflectivity * cos(incidence) * share / range^2        (1/m^2, "power" below)
// where `share` is the part of the beam's energy that hit it (1 for a single ray). The
// "apparent reflectivity" of a return is p * range^2.
#pragma once

#include <array>
#include <vector>

namespace livo::sim {

/// `sim.lidar` effect options; every default switches its effect off.
struct LidarEffects {
  // range noise std = sqrt(range_noise_std^2 + (range_noise_per_m * range * (0.5 / apparent)^exponent)^2)
  double range_noise_per_m = 0.0;            // m per m of range, for a 50 % target at normal incidence
  double noise_reflectivity_exponent = 0.5;  // 0.5: shot-noise limited receiver; 0: no reflectivity penalty
  // detection probability = Phi(ln(p / p10) / detection_softness + z90), p10 = 0.1 / max_range_at_10pct^2:
  // 90 % for a 10 % target at normal incidence at max_range_at_10pct
  double max_range_at_10pct = 0.0;  // m; 0: every return is detected
  double detection_softness = 0.2;  // std of ln(power) at the threshold (width of the edge)
  // Gaussian beam of these full widths at half maximum, sampled by 7 sub-rays
  std::array<double, 2> beam_divergence_mrad{{0.0, 0.0}};  // horizontal (along the scan), vertical
  double echo_separation_m = 1.0;                          // echoes closer than this merge into one (mixed pixel)

  bool detection() const { return max_range_at_10pct > 0.0; }
  bool footprint() const { return beam_divergence_mrad[0] > 0.0 || beam_divergence_mrad[1] > 0.0; }
  bool any() const { return range_noise_per_m > 0.0 || detection() || footprint(); }
};

/// Apparent reflectivity below which the noise penalty stops growing (grazing returns).
constexpr double kMinApparentReflectivity = 0.01;
/// Reflectivity at which `range_noise_per_m` is quoted.
constexpr double kNoiseReferenceReflectivity = 0.5;
/// Probability of detection of the datasheet's range figure (10 % target at max_range_at_10pct).
constexpr double kDetectionAtRatedRange = 0.9;

/// Std (m) of the range noise of a return at `range` with `apparent_reflectivity`; exactly
/// `base_std` when range_noise_per_m is 0.
double rangeNoiseStd(const LidarEffects& e, double base_std, double range, double apparent_reflectivity);

/// Probability that the receiver detects a return at `range` with `apparent_reflectivity`
/// (1 when the detection model is off).
double detectionProbability(const LidarEffects& e, double range, double apparent_reflectivity);

/// One sub-ray of the beam footprint: angular offsets (rad) from the beam axis along the
/// horizontal (scan) and vertical directions, and its share of the beam energy.
struct SubRay {
  double horizontal = 0.0, vertical = 0.0;
  double weight = 1.0;
};
/// The footprint sampling: the centre and six points on the half-maximum ellipse of a Gaussian
/// spot, weighted by the Gaussian there (1 and 1/2, normalised to 1/4 and 1/8).
std::vector<SubRay> footprintSubRays(const LidarEffects& e);

/// A sub-ray's hit: range along the sub-ray and what the surface sends back.
struct SubRayHit {
  double range = 0.0;
  double weight = 0.0;
  double reflectivity = 0.0;
  double cos_incidence = 1.0;
  double power() const { return weight * reflectivity * cos_incidence / (range * range); }
};

/// The return the receiver reports, as a range along the beam axis. Intensity is
/// 255 * reflectivity * cos_incidence * share.
struct Echo {
  double range = -1.0;         // < 0: no return
  double reflectivity = 0.0;   // a merged echo carries its apparent reflectivity / share here
  double cos_incidence = 1.0;  //   and 1 here
  double share = 1.0;          // part of the beam energy in this echo
  bool valid() const { return range >= 0.0; }
  double apparentReflectivity() const { return reflectivity * cos_incidence * share; }
};

/// Strongest-return receiver: sub-ray hits within `separation` of the nearest hit of their group
/// merge into one echo at their power-weighted mean range (a mixed pixel); of the groups, the one
/// with the most power is reported. `hits` is reordered; empty gives no echo.
Echo strongestEcho(std::vector<SubRayHit>* hits, double separation);

}  // namespace livo::sim
