// The readings of a time-ordered sample buffer (IMU, wheel) over an interval, as preintegration
// between two states needs them: the readings at both ends interpolated, every sample between.
// Shared by livo-lio-graph and livo-vio-feature.
#pragma once

#include <cstdint>
#include <deque>
#include <vector>

#include "livo/sensor_samples.hpp"

namespace livo {

/// IMU reading at t between two samples (linear).
inline ImuSample interpolate(const ImuSample& a, const ImuSample& b, int64_t t) {
  if (b.utime <= a.utime) return ImuSample{t, b.gyro, b.accel};
  const double s = static_cast<double>(t - a.utime) / static_cast<double>(b.utime - a.utime);
  return ImuSample{t, a.gyro + s * (b.gyro - a.gyro), a.accel + s * (b.accel - a.accel)};
}

/// Wheel reading at t between two samples (linear).
inline WheelSample interpolate(const WheelSample& a, const WheelSample& b, int64_t t) {
  if (b.utime <= a.utime) return WheelSample{t, b.left_speed, b.right_speed};
  const double s = static_cast<double>(t - a.utime) / static_cast<double>(b.utime - a.utime);
  return WheelSample{t, a.left_speed + s * (b.left_speed - a.left_speed),
                     a.right_speed + s * (b.right_speed - a.right_speed)};
}

/// Samples of a time-ordered buffer covering [t0, t1]: the readings at t0 and t1 (interpolated;
/// held before the first sample) and every sample strictly between. False if the buffer does not
/// reach t1.
template <class Sample>
bool samplesOver(const std::deque<Sample>& buf, int64_t t0, int64_t t1, std::vector<Sample>* out) {
  out->clear();
  if (buf.empty() || buf.back().utime < t1) return false;
  size_t i = 0;
  while (i + 1 < buf.size() && buf[i + 1].utime <= t0) ++i;
  if (buf[i].utime >= t0 || i + 1 >= buf.size()) {
    Sample s = buf[i];
    s.utime = t0;
    out->push_back(s);
  } else {
    out->push_back(interpolate(buf[i], buf[i + 1], t0));
  }
  for (size_t k = i; k < buf.size() && buf[k].utime < t1; ++k)
    if (buf[k].utime > t0) out->push_back(buf[k]);
  size_t j = 0;
  while (j < buf.size() && buf[j].utime < t1) ++j;
  out->push_back(j == 0 ? buf[0] : interpolate(buf[j - 1], buf[j], t1));
  out->back().utime = t1;
  return true;
}

}  // namespace livo
