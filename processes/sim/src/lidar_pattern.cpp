#include "livo/sim/lidar_pattern.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace livo::sim {

namespace {
constexpr double kDeg = M_PI / 180.0;

// Livox-style rosette: two counter-rotating prisms (Hz) deflecting by half the field radius each.
constexpr double kPrismHz1 = 121.57, kPrismHz2 = 77.73;
constexpr double kRosetteRadius = 38.6 * kDeg;
constexpr double kSolidStateFiringHz = 40000.0;  // 6 lasers each => 240k points/s

void assignRingsByElevation(std::vector<double> elevations, std::vector<int>* rings) {
  std::vector<int> order(elevations.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return elevations[a] < elevations[b]; });
  rings->assign(elevations.size(), 0);
  for (size_t r = 0; r < order.size(); ++r) (*rings)[order[r]] = static_cast<int>(r);
}
}  // namespace

const std::vector<std::string>& LidarPattern::models() {
  static const std::vector<std::string> kModels = {"VLP-16", "HDL-64E", "OS1-16", "OS1-64", "livox-avia"};
  return kModels;
}

LidarPattern::LidarPattern(const std::string& model, double rate_hz, const LidarPatternOptions& options) {
  if (!(rate_hz > 0.0)) throw std::invalid_argument("LiDAR rate must be > 0");
  sweep_duration_ = 1.0 / rate_hz;
  start_azimuth_ = options.start_azimuth_deg * kDeg;
  std::vector<double> elevation, azimuth, firing;
  int default_columns = 0;
  if (model == "VLP-16") {
    // laser ids in firing order, 2.304 us apart; 55.296 us firing cycle
    for (int id = 0; id < 16; ++id) {
      elevation.push_back((id % 2 == 0 ? -15.0 + id : 1.0 + (id - 1)) * kDeg);
      azimuth.push_back(0.0);
      firing.push_back(id * 2.304e-6);
    }
    default_columns = static_cast<int>(std::lround(sweep_duration_ / 55.296e-6));
  } else if (model == "HDL-64E") {
    // upper block +2.0 .. -8.33 deg, lower block -8.83 .. -24.33 deg; one upper and one lower laser
    // fire together, 32 pairs 1.44 us apart in a 48 us cycle
    for (int k = 0; k < 32; ++k) {
      elevation.push_back((2.0 - k * (10.33 / 31.0)) * kDeg);
      azimuth.push_back(0.0);
      firing.push_back(k * 1.44e-6);
      elevation.push_back((-8.83 - k * 0.5) * kDeg);
      azimuth.push_back(0.0);
      firing.push_back(k * 1.44e-6);
    }
    default_columns = static_cast<int>(std::lround(sweep_duration_ / 48.0e-6));
  } else if (model == "OS1-16" || model == "OS1-64") {
    // 33.2 deg vertical field, all channels of a column fire together; OS1-64 beams are staggered
    // in azimuth in a repeating pattern of four
    const int n = model == "OS1-16" ? 16 : 64;
    const double stagger[4] = {3.164, 1.055, -1.055, -3.164};
    for (int k = 0; k < n; ++k) {
      elevation.push_back((16.6 - k * 33.2 / (n - 1)) * kDeg);
      azimuth.push_back(n == 64 ? stagger[k % 4] * kDeg : 0.0);
      firing.push_back(0.0);
    }
    default_columns = 1024;
  } else if (model == "livox-avia") {
    solid_state_ = true;
    for (int k = 0; k < 6; ++k) {
      elevation.push_back((k - 2.5) * 0.8 * kDeg);
      azimuth.push_back(0.0);
      firing.push_back(0.0);
    }
    default_columns = static_cast<int>(std::lround(sweep_duration_ * kSolidStateFiringHz));
  } else {
    throw std::invalid_argument("unknown LiDAR model '" + model + "'");
  }
  columns_ = options.columns > 0 ? options.columns : default_columns;
  if (columns_ < 1) throw std::invalid_argument("LiDAR needs at least one firing per sweep");
  std::vector<int> rings;
  if (solid_state_) {
    rings.resize(elevation.size());
    std::iota(rings.begin(), rings.end(), 0);
  } else {
    assignRingsByElevation(elevation, &rings);
  }
  for (size_t b = 0; b < elevation.size(); ++b) {
    if (firing[b] >= columnPeriod())
      throw std::invalid_argument(model + ": too many firings per sweep for the beam schedule");
    beams_.push_back({elevation[b], azimuth[b], firing[b], rings[b]});
  }
}

Vec3 LidarPattern::direction(int beam, double sweep_time, double sensor_time) const {
  const Beam& b = beams_[beam];
  if (!solid_state_) {
    const double az = start_azimuth_ - 2.0 * M_PI * sweep_time / sweep_duration_ + b.azimuth_offset;
    const double ce = std::cos(b.elevation);
    return Vec3(ce * std::cos(az), ce * std::sin(az), std::sin(b.elevation));
  }
  const double p1 = 2.0 * M_PI * kPrismHz1 * sensor_time, p2 = 2.0 * M_PI * kPrismHz2 * sensor_time;
  const double h = 0.5 * kRosetteRadius * (std::cos(p1) + std::cos(p2)) + b.azimuth_offset;  // horizontal
  const double v = 0.5 * kRosetteRadius * (std::sin(p1) - std::sin(p2)) + b.elevation;       // vertical
  const double theta = std::hypot(h, v), phi = std::atan2(v, h);
  const double st = std::sin(theta);
  return Vec3(std::cos(theta), st * std::cos(phi), st * std::sin(phi));
}

}  // namespace livo::sim
