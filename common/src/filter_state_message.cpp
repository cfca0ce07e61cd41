#include "livo/filter_state_message.hpp"

#include <cmath>

#include "livo/messages.hpp"

namespace livo {

namespace {
bool unitQuaternion(const double q[4]) {
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  return n > 0.5 && n < 2.0;
}
}  // namespace

filter_state_t toFilterState(int64_t utime, const FilterState& x, const StateCovariance& P, int64_t request_id,
                             const std::string& source, const Vec3& body_rate) {
  filter_state_t m;
  m.utime = utime;
  m.request_id = request_id;
  m.source = source;
  m.epoch = 0;  // the caller sets the frame (odometry epoch and loop correction) the state is in
  m.correction_id = 0;
  quatToWxyz(Quat(x.rot), m.orientation);
  vec3To(x.pos, m.position);
  vec3To(x.vel, m.velocity);
  vec3To(x.gyro_bias, m.gyro_bias);
  vec3To(x.accel_bias, m.accel_bias);
  vec3To(x.gravity, m.gravity);
  vec3To(body_rate, m.angular_velocity);
  quatToWxyz(Quat(x.lidar.rot), m.lidar_orientation);
  vec3To(x.lidar.pos, m.lidar_position);
  m.lidar_time_shift = x.lidar.dt;
  quatToWxyz(Quat(x.camera.rot), m.camera_orientation);
  vec3To(x.camera.pos, m.camera_position);
  m.camera_time_shift = x.camera.dt;
  matrixTo<FilterState::kDim>(P, m.covariance);
  m.valid = 1;
  m.iterations = 0;
  m.num_measurements = 0;
  return m;
}

bool fromFilterState(const filter_state_t& m, FilterState* x, StateCovariance* P) {
  constexpr int n = FilterState::kDim;
  if (!allFinite(m.orientation, 4) || !allFinite(m.position, 3) || !allFinite(m.velocity, 3) ||
      !allFinite(m.gyro_bias, 3) || !allFinite(m.accel_bias, 3) || !allFinite(m.gravity, 3) ||
      !allFinite(m.angular_velocity, 3) || !allFinite(m.lidar_orientation, 4) || !allFinite(m.lidar_position, 3) ||
      !std::isfinite(m.lidar_time_shift) || !allFinite(m.camera_orientation, 4) || !allFinite(m.camera_position, 3) ||
      !std::isfinite(m.camera_time_shift) || !allFinite(m.covariance, n * n))
    return false;
  if (!unitQuaternion(m.orientation) || !unitQuaternion(m.lidar_orientation) || !unitQuaternion(m.camera_orientation))
    return false;
  x->rot = quatFromWxyz(m.orientation).toRotationMatrix();
  x->pos = vec3From(m.position);
  x->vel = vec3From(m.velocity);
  x->gyro_bias = vec3From(m.gyro_bias);
  x->accel_bias = vec3From(m.accel_bias);
  x->gravity = vec3From(m.gravity);
  x->lidar = SensorCalibration{quatFromWxyz(m.lidar_orientation).toRotationMatrix(), vec3From(m.lidar_position),
                               m.lidar_time_shift};
  x->camera = SensorCalibration{quatFromWxyz(m.camera_orientation).toRotationMatrix(), vec3From(m.camera_position),
                                m.camera_time_shift};
  *P = matrixFrom<n>(m.covariance);
  return true;
}

}  // namespace livo
