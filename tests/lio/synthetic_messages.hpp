// The synthetic world's samples as the LCM messages a sensor driver would publish (for the node
// tests of livo-lio and livo-lio-graph). The ring of a point is its synthetic intensity, which the
// synthetic LiDAR sets to the beam index.
#pragma once

#include "livo/imu_t.hpp"
#include "livo/messages.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/sensor_samples.hpp"

namespace livo::lio::synth {

inline imu_t imuMessage(const ImuSample& s) {
  imu_t m;
  m.utime = s.utime;
  vec3To(s.gyro, m.angular_velocity);
  vec3To(s.accel, m.linear_acceleration);
  return m;
}

inline point_cloud_t cloudMessage(const LidarScan& s) {
  point_cloud_t m;
  m.utime = s.utime;
  m.frame = "L";
  m.pattern = point_cloud_t::PATTERN_SPINNING;
  m.num_rings = 16;
  m.sweep_duration = static_cast<float>(s.sweep_duration);
  m.num_points = static_cast<int32_t>(s.points.size());
  for (size_t i = 0; i < s.points.size(); ++i) {
    m.x.push_back(static_cast<float>(s.points[i].x()));
    m.y.push_back(static_cast<float>(s.points[i].y()));
    m.z.push_back(static_cast<float>(s.points[i].z()));
    m.intensity.push_back(s.intensity[i]);
    m.time_offset.push_back(s.time_offset[i]);
    m.ring.push_back(static_cast<int16_t>(s.intensity[i]));
  }
  return m;
}

}  // namespace livo::lio::synth
