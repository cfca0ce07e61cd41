#include "livo/import/ros_messages.hpp"

namespace livo::import {

RosImu decodeRosImu(ByteReader& r) {
  RosImu m;
  m.header = decodeRosHeader(r);
  const char* q[4] = {"orientation.x", "orientation.y", "orientation.z", "orientation.w"};
  for (int i = 0; i < 4; ++i) m.orientation_xyzw[i] = r.f64(q[i]);
  r.skip(9 * 8, "orientation_covariance");
  const char* w[3] = {"angular_velocity.x", "angular_velocity.y", "angular_velocity.z"};
  for (int i = 0; i < 3; ++i) m.angular_velocity[i] = r.f64(w[i]);
  r.skip(9 * 8, "angular_velocity_covariance");
  const char* a[3] = {"linear_acceleration.x", "linear_acceleration.y", "linear_acceleration.z"};
  for (int i = 0; i < 3; ++i) m.linear_acceleration[i] = r.f64(a[i]);
  r.skip(9 * 8, "linear_acceleration_covariance");
  return m;
}

}  // namespace livo::import
