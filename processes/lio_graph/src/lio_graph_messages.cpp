#include "livo/lio_graph/lio_graph_messages.hpp"

#include "livo/messages.hpp"
#include "livo/odometry_message.hpp"
#include "livo/output_messages.hpp"

namespace livo::lio_graph {

VisualSample toVisualSample(const visual_state_t& m) {
  VisualSample s;
  s.utime = m.utime;
  s.pose = poseFrom(m.position, m.orientation);
  s.epoch = m.epoch;
  return s;
}

odometry_t toOdometry(const GraphScanResult& r, const OdometryFrame& frame) {
  OdometryOutput o;
  o.utime = r.utime;
  o.pose = r.pose;
  o.velocity = r.velocity;
  o.angular_velocity = r.angular_velocity;
  o.pose_covariance = r.pose_covariance;
  o.velocity_covariance = Mat3::Identity() * 1e-2;
  // a predicted sweep used none: its matching, if any, was not taken
  o.num_residuals = r.status == GraphScanResult::Status::kPredicted ? 0 : r.edge_residuals + r.surface_residuals;
  o.degenerate = r.degenerate;
  return odometryMessage(o, OutputFrame{frame.epoch, frame.correction_id});
}

registered_scan_t toRegisteredScan(const GraphScanResult& r, const point_cloud_t& input, const OdometryFrame& frame) {
  return registeredScanMessage(r.utime, r.sweep_start_utime, r.pose, r.world_points, r.input_index, input,
                               OutputFrame{frame.epoch, frame.correction_id});
}

keyframe_t toKeyframe(const GraphKeyframe& k, int16_t num_rings, const OdometryFrame& frame) {
  return keyframeMessage(k.id, k.utime, k.pose, k.pose_covariance, KeyframeIncrement{}, k.cloud, k.intensity, num_rings,
                         OutputFrame{frame.epoch, frame.correction_id});
}

}  // namespace livo::lio_graph
