// test-playback-log-writer OUT SECONDS: IMU at 100 Hz, LIDAR at 10 Hz and GROUND_TRUTH at 20 Hz
// (a circle of 5 m radius at 0.2 rad/s): the log of the playback and pipeline-runner tests.
#include <cmath>
#include <cstdlib>
#include <iostream>

#include "livo/pose_t.hpp"
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
    if (i % 5 == 0) {
      const double t = i * 0.01, a = 0.2 * t;
      livo::pose_t gt{};
      gt.utime = m.utime;
      gt.parent_frame = "W";
      gt.child_frame = "I";
      gt.position[0] = 5.0 * std::cos(a);
      gt.position[1] = 5.0 * std::sin(a);
      gt.position[2] = 1.0;
      gt.orientation[0] = std::cos(0.5 * (a + M_PI / 2));  // heading along the circle
      gt.orientation[3] = std::sin(0.5 * (a + M_PI / 2));
      playback_test::writeEvent(log, "GROUND_TRUTH", gt);
    }
  }
  return 0;
}
