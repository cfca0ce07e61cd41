#include "livo/sensor_messages.hpp"

#include <algorithm>

#include "livo/messages.hpp"

namespace livo {

ImuSample fromMessage(const imu_t& m) {
  ImuSample s;
  s.utime = m.utime;
  s.gyro = vec3From(m.angular_velocity);
  s.accel = vec3From(m.linear_acceleration);
  return s;
}

WheelSample fromMessage(const wheel_odometry_t& m) { return WheelSample{m.utime, m.left_speed, m.right_speed}; }

bool fromMessage(const point_cloud_t& m, LidarScan* scan, std::string* why) {
  const size_t n = static_cast<size_t>(std::max(0, m.num_points));
  if (m.x.size() != n || m.y.size() != n || m.z.size() != n || m.time_offset.size() != n ||
      (!m.intensity.empty() && m.intensity.size() != n)) {
    *why = "point cloud arrays differ from num_points";
    return false;
  }
  if (m.frame != "L") {
    *why = "point cloud in frame '" + m.frame + "', expected 'L'";
    return false;
  }
  scan->utime = m.utime;
  scan->sweep_duration = m.sweep_duration;
  scan->points.resize(n);
  scan->time_offset.assign(m.time_offset.begin(), m.time_offset.end());
  scan->intensity.assign(m.intensity.begin(), m.intensity.end());
  if (m.ring.size() == n)
    scan->ring.assign(m.ring.begin(), m.ring.end());
  else
    scan->ring.clear();
  for (size_t i = 0; i < n; ++i) scan->points[i] = Vec3(m.x[i], m.y[i], m.z[i]);
  return true;
}

}  // namespace livo
