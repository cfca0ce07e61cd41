#include "livo/import/imu_units.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace livo::import {

ImuUnitNormaliser::ImuUnitNormaliser(ImuUnitOptions options, std::string source, ImportReport& report, Emit emit)
    : options_(std::move(options)), source_(std::move(source)), report_(report), emit_(std::move(emit)) {
  if (options_.gyro == "deg/s")
    gyro_scale_ = M_PI / 180.0;
  else if (options_.gyro != "rad/s")
    throw std::invalid_argument("unknown gyro unit '" + options_.gyro + "' (rad/s or deg/s)");
  if (options_.accel == "g") {
    accel_scale_ = kStandardGravity, decided_ = true;
  } else if (options_.accel == "m/s2") {
    decided_ = true;
  } else if (options_.accel != "auto") {
    throw std::invalid_argument("unknown acceleration unit '" + options_.accel + "' (auto, m/s2 or g)");
  }
}

void ImuUnitNormaliser::emitConverted(imu_t s) const {
  for (int i = 0; i < 3; ++i) {
    s.linear_acceleration[i] *= accel_scale_;
    s.angular_velocity[i] *= gyro_scale_;
  }
  emit_(s);
}

void ImuUnitNormaliser::add(const imu_t& sample) {
  if (decided_) return emitConverted(sample);
  pending_.push_back(sample);
  if (static_cast<int>(pending_.size()) >= options_.samples_to_decide) decide();
}

void ImuUnitNormaliser::decide() {
  std::vector<double> norms;
  for (const imu_t& s : pending_)
    norms.push_back(std::sqrt(s.linear_acceleration[0] * s.linear_acceleration[0] +
                              s.linear_acceleration[1] * s.linear_acceleration[1] +
                              s.linear_acceleration[2] * s.linear_acceleration[2]));
  if (!norms.empty()) {
    std::nth_element(norms.begin(), norms.begin() + norms.size() / 2, norms.end());
    const double median = norms[norms.size() / 2];
    if (median > 0.5 && median < 2.0) {
      accel_scale_ = kStandardGravity;
      std::ostringstream os;
      os << source_ << ": linear_acceleration median |a| = " << median
         << " looks like g, converted to m/s^2 (force with --imu-accel-unit)";
      report_.note(os.str());
    }
  }
  decided_ = true;
  for (const imu_t& s : pending_) emitConverted(s);
  pending_.clear();
}

void ImuUnitNormaliser::flush() {
  if (!decided_) decide();
}

}  // namespace livo::import
