#include "livo/filter_state_message.hpp"

#include <cmath>

#include "livo/messages.hpp"

namespace livo {

filter_state_t toFilterState(int64_t utime, const FilterState& x, const Mat18& P, int64_t request_id,
                             const std::string& source) {
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
  matrixTo<18>(P, m.covariance);
  m.valid = 1;
  m.iterations = 0;
  m.num_measurements = 0;
  return m;
}

bool fromFilterState(const filter_state_t& m, FilterState* x, Mat18* P) {
  if (!allFinite(m.orientation, 4) || !allFinite(m.position, 3) || !allFinite(m.velocity, 3) ||
      !allFinite(m.gyro_bias, 3) || !allFinite(m.accel_bias, 3) || !allFinite(m.gravity, 3) ||
      !allFinite(m.covariance, 324))
    return false;
  const double qn = std::sqrt(m.orientation[0] * m.orientation[0] + m.orientation[1] * m.orientation[1] +
                              m.orientation[2] * m.orientation[2] + m.orientation[3] * m.orientation[3]);
  if (!(qn > 0.5 && qn < 2.0)) return false;
  x->rot = quatFromWxyz(m.orientation).toRotationMatrix();
  x->pos = vec3From(m.position);
  x->vel = vec3From(m.velocity);
  x->gyro_bias = vec3From(m.gyro_bias);
  x->accel_bias = vec3From(m.accel_bias);
  x->gravity = vec3From(m.gravity);
  *P = matrixFrom<18>(m.covariance);
  return true;
}

}  // namespace livo
