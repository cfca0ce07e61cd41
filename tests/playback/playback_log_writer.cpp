// test-playback-log-writer OUT SECONDS: IMU at 100 Hz and LIDAR at 10 Hz (the playback test log).
#include <cstdlib>
#include <iostream>

#include "test_log.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: test-playback-log-writer OUT SECONDS\n";
    return 2;
  }
  lcm::LogFile log(argv[1], "w");
  const int n = static_cast<int>(std::atof(argv[2]) * 100);
  for (int i = 0; i < n; ++i) {
    livo::imu_t m{};
    m.utime = playback_test::kT0 + i * 10000;
    m.angular_velocity[0] = i;
    playback_test::writeEvent(log, "IMU", m);
    if (i % 10 == 5) playback_test::writeEvent(log, "LIDAR", playback_test::cloudAt(m.utime, 200));
  }
  return 0;
}
