#include "livo/sim/wheel_model.hpp"

namespace livo::sim {

WheelReading idealWheelReading(const BodyState& s, const WheelRig& rig, int64_t utime) {
  const Mat3 R_WI = s.T_W_I.linear();
  const Mat3 R_IB = rig.T_I_B.linear();
  const Vec3 r_IB = rig.T_I_B.translation();
  // velocity of the base origin in the world, then in B; body rate in B
  const Vec3 v_W = s.velocity + R_WI * s.angular_velocity.cross(r_IB);
  const Vec3 v_B = R_IB.transpose() * (R_WI.transpose() * v_W);
  const Vec3 w_B = R_IB.transpose() * s.angular_velocity;
  WheelReading r;
  r.utime = utime;
  r.left_speed = v_B.x() - 0.5 * rig.track_width * w_B.z();
  r.right_speed = v_B.x() + 0.5 * rig.track_width * w_B.z();
  return r;
}

}  // namespace livo::sim
