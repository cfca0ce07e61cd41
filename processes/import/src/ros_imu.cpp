#include "ros_decoding.hpp"

namespace livo::import {

namespace {
template <class Reader>
RosImu decodeImu(Reader& r) {
  RosImu m;
  m.header = detail::decodeHeader(r);
  const char* q[4] = {"orientation.x", "orientation.y", "orientation.z", "orientation.w"};
  for (int i = 0; i < 4; ++i) m.orientation_xyzw[i] = r.f64(q[i]);
  r.skipF64(9, "orientation_covariance");
  const char* w[3] = {"angular_velocity.x", "angular_velocity.y", "angular_velocity.z"};
  for (int i = 0; i < 3; ++i) m.angular_velocity[i] = r.f64(w[i]);
  r.skipF64(9, "angular_velocity_covariance");
  const char* a[3] = {"linear_acceleration.x", "linear_acceleration.y", "linear_acceleration.z"};
  for (int i = 0; i < 3; ++i) m.linear_acceleration[i] = r.f64(a[i]);
  r.skipF64(9, "linear_acceleration_covariance");
  return m;
}
}  // namespace

RosImu decodeRosImu(ByteReader& r) { return decodeImu(r); }
RosImu decodeCdrImu(CdrReader& r) { return decodeImu(r); }

}  // namespace livo::import
