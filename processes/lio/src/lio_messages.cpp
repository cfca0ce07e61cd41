#include "livo/lio/lio_messages.hpp"

#include <cmath>

#include "livo/messages.hpp"
#include "livo/output_messages.hpp"
#include "livo/time.hpp"

namespace livo::lio {

odometry_t toOdometry(const ScanResult& r, const OdometryFrame& frame) {
  odometry_t o;
  o.utime = r.utime;
  o.parent_frame = "W";
  o.child_frame = "I";
  poseTo(r.state.pose(), o.position, o.orientation);
  vec3To(r.state.vel, o.velocity);
  vec3To(r.angular_velocity, o.angular_velocity);
  matrixTo<6>(Mat6(r.covariance.topLeftCorner<6, 6>()), o.pose_covariance);
  matrixTo<3>(Mat3(r.covariance.block<3, 3>(FilterState::kVel, FilterState::kVel)), o.velocity_covariance);
  // a predicted sweep used none: its registration, if any, was not taken
  o.num_residuals = r.status == ScanResult::Status::kPredicted ? 0 : r.num_residuals;
  o.degenerate = r.degeneracy.degenerate ? 1 : 0;
  o.min_information_eigenvalue = r.min_information_eigenvalue;
  o.epoch = frame.epoch;
  o.correction_id = frame.correction_id;
  return o;
}

registered_scan_t toRegisteredScan(const ScanResult& r, const point_cloud_t& in, const OdometryFrame& frame) {
  return registeredScanMessage(r.utime, r.sweep_start_utime, r.state.pose(), r.world_points, r.input_index, in,
                               OutputFrame{frame.epoch, frame.correction_id});
}

keyframe_t toKeyframe(const Keyframe& k, int16_t num_rings, const OdometryFrame& frame) {
  const KeyframeIncrement increment{k.relative_to_id, k.relative_covariance, k.relative_covariance_held_calibration};
  return keyframeMessage(k.id, k.utime, k.pose, k.pose_covariance, increment, k.cloud, k.intensity, num_rings,
                         OutputFrame{frame.epoch, frame.correction_id});
}

}  // namespace livo::lio
