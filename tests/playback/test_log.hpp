// A small synthetic log for the playback tests: IMU at 100 Hz and point clouds at 10 Hz.
#pragma once

#include <unistd.h>
#include <string>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "livo/imu_t.hpp"
#include "livo/point_cloud_t.hpp"
#include "temp_path.hpp"

namespace playback_test {

constexpr int64_t kT0 = 1700000000000000;

template <class T>
void writeEvent(lcm::LogFile& log, const std::string& channel, const T& m) {
  std::vector<uint8_t> buf(m.getEncodedSize());
  m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  lcm::LogEvent ev;
  ev.timestamp = m.utime;
  ev.channel = channel;
  ev.datalen = static_cast<int32_t>(buf.size());
  ev.data = buf.data();
  log.writeEvent(&ev);
}

inline livo::point_cloud_t cloudAt(int64_t utime, int n) {
  livo::point_cloud_t c{};
  c.utime = utime;
  c.frame = "L";
  c.num_points = n;
  for (int i = 0; i < n; ++i) {
    c.x.push_back(1.0f + i), c.y.push_back(2.0f), c.z.push_back(3.0f), c.intensity.push_back(0.f);
    c.time_offset.push_back(1e-4f * i), c.ring.push_back(static_cast<int16_t>(i % 16));
  }
  return c;
}

/// `seconds` of IMU (100 Hz) and LIDAR (10 Hz, 200 points); returns the path.
inline std::string makeLog(const std::string& name, double seconds) {
  // ctest runs the tests of one executable as parallel processes: one file per process.
  const std::string path = livo_test::tempPath(name + ".lcmlog");
  lcm::LogFile log(path, "w");
  const int n = static_cast<int>(seconds * 100);
  for (int i = 0; i < n; ++i) {
    livo::imu_t m{};
    m.utime = kT0 + i * 10000;
    m.angular_velocity[0] = i;
    writeEvent(log, "IMU", m);
    if (i % 10 == 5) writeEvent(log, "LIDAR", cloudAt(m.utime, 200));
  }
  return path;
}

}  // namespace playback_test
