#include "livo/vio_feature/vio_feature_messages.hpp"

#include "livo/messages.hpp"
#include "livo/odometry_message.hpp"

namespace livo::vio_feature {

BodyScan toBodyScan(const registered_scan_t& m, const Pose3& T_I_C, double min_depth) {
  const Pose3 T_I_W = poseFrom(m.position, m.orientation).inverse();
  const Pose3 T_C_I = T_I_C.inverse();
  BodyScan s;
  s.t = m.utime;
  const point_cloud_t& c = m.cloud;
  s.points_I.reserve(static_cast<size_t>(c.num_points) / 2);
  for (int32_t i = 0; i < c.num_points; ++i) {
    const Vec3 p_I = T_I_W * Vec3(c.x[i], c.y[i], c.z[i]);
    if ((T_C_I * p_I).z() > min_depth) s.points_I.push_back(p_I);
  }
  return s;
}

visual_state_t toVisualState(const FrameResult& r, int32_t epoch) {
  const VisualState& s = r.state;
  visual_state_t v;
  v.utime = s.utime;
  poseTo(s.pose, v.position, v.orientation);
  vec3To(s.velocity, v.velocity);
  vec3To(s.gyro_bias, v.gyro_bias);
  vec3To(s.accel_bias, v.accel_bias);
  matrixTo<6>(s.pose_covariance, v.pose_covariance);
  v.status = r.status == FrameResult::Status::kInitialized ? visual_state_t::STATUS_INITIALIZED
                                                           : visual_state_t::STATUS_TRACKING;
  v.features = r.features_in_graph;
  v.features_with_depth = r.features_with_depth;
  v.epoch = epoch;
  return v;
}

odometry_t toOdometry(const FrameResult& r, int32_t epoch) {
  const VisualState& s = r.state;
  OdometryOutput o;
  o.utime = s.utime;
  o.parent_frame = "V";
  o.pose = s.pose;
  o.velocity = s.velocity;
  o.pose_covariance = s.pose_covariance;
  o.velocity_covariance = Mat3::Identity() * 1e-2;
  o.num_residuals = 2 * r.features_in_graph;
  o.degenerate = r.features_in_graph < 20;
  return odometryMessage(o, OutputFrame{epoch, 0});
}

}  // namespace livo::vio_feature
