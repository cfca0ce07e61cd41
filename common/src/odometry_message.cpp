#include "livo/odometry_message.hpp"

#include "livo/messages.hpp"

namespace livo {

odometry_t odometryMessage(const OdometryOutput& o, const OutputFrame& frame) {
  odometry_t m;
  m.utime = o.utime;
  m.parent_frame = o.parent_frame;
  m.child_frame = "I";
  poseTo(o.pose, m.position, m.orientation);
  vec3To(o.velocity, m.velocity);
  vec3To(o.angular_velocity, m.angular_velocity);
  matrixTo<6>(o.pose_covariance, m.pose_covariance);
  matrixTo<3>(o.velocity_covariance, m.velocity_covariance);
  m.num_residuals = o.num_residuals;
  m.degenerate = o.degenerate ? 1 : 0;
  m.min_information_eigenvalue = o.min_information_eigenvalue;
  m.epoch = frame.epoch;
  m.correction_id = frame.correction_id;
  return m;
}

}  // namespace livo
