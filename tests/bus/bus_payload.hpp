// The test payload: a ~1 MB point cloud whose every value is a function of its sequence number,
// so the subscriber can check each message bit for bit.
#pragma once

#include <cstdint>

#include "livo/point_cloud_t.hpp"

namespace bus_test {

constexpr int kPoints = 48000;  // 22 bytes a point: ~1.06 MB a message
constexpr int kMessages = 50;   // 5 s at 10 Hz

inline float valueAt(int64_t seq, int i, int field) {
  return static_cast<float>((seq * 131 + i * 7 + field * 17) % 10007) * 0.01f;
}

inline livo::point_cloud_t makeCloud(int64_t seq) {
  livo::point_cloud_t c;
  c.utime = seq;
  c.frame = "L";
  c.pattern = livo::point_cloud_t::PATTERN_SPINNING;
  c.num_rings = 16;
  c.sweep_duration = 0.1f;
  c.num_points = kPoints;
  c.x.resize(kPoints), c.y.resize(kPoints), c.z.resize(kPoints);
  c.intensity.resize(kPoints), c.time_offset.resize(kPoints), c.ring.resize(kPoints);
  for (int i = 0; i < kPoints; ++i) {
    c.x[i] = valueAt(seq, i, 0);
    c.y[i] = valueAt(seq, i, 1);
    c.z[i] = valueAt(seq, i, 2);
    c.intensity[i] = valueAt(seq, i, 3);
    c.time_offset[i] = valueAt(seq, i, 4);
    c.ring[i] = static_cast<int16_t>(i % 16);
  }
  return c;
}

inline bool intact(const livo::point_cloud_t& c) {
  if (c.num_points != kPoints || c.frame != "L") return false;
  for (int i = 0; i < kPoints; ++i) {
    const int64_t s = c.utime;
    if (c.x[i] != valueAt(s, i, 0) || c.y[i] != valueAt(s, i, 1) || c.z[i] != valueAt(s, i, 2) ||
        c.intensity[i] != valueAt(s, i, 3) || c.time_offset[i] != valueAt(s, i, 4) || c.ring[i] != i % 16)
      return false;
  }
  return true;
}

}  // namespace bus_test
