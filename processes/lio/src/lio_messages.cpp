#include "livo/lio/lio_messages.hpp"

#include <cmath>

#include "livo/messages.hpp"
#include "livo/odometry_message.hpp"
#include "livo/output_messages.hpp"
#include "livo/time.hpp"

namespace livo::lio {

odometry_t toOdometry(const ScanResult& r, const OdometryFrame& frame) {
  OdometryOutput o;
  o.utime = r.utime;
  o.pose = r.state.pose();
  o.velocity = r.state.vel;
  o.angular_velocity = r.angular_velocity;
  o.pose_covariance = r.covariance.topLeftCorner<6, 6>();
  o.velocity_covariance = r.covariance.block<3, 3>(FilterState::kVel, FilterState::kVel);
  // a predicted sweep used none: its registration, if any, was not taken
  o.num_residuals = r.status == ScanResult::Status::kPredicted ? 0 : r.num_residuals;
  o.degenerate = r.degeneracy.degenerate;
  o.min_information_eigenvalue = r.min_information_eigenvalue;
  return odometryMessage(o, OutputFrame{frame.epoch, frame.correction_id});
}

registered_scan_t toRegisteredScan(const ScanResult& r, const point_cloud_t& in, const OdometryFrame& frame) {
  return registeredScanMessage(r.utime, r.sweep_start_utime, r.state.pose(), r.world_points, r.input_index, in,
                               OutputFrame{frame.epoch, frame.correction_id});
}

registered_scan_t toRegisteredScan(const ScanResult& r, const LidarScan& input, const SweepFormat& format,
                                   const OdometryFrame& frame) {
  // the fields registeredScanMessage reads (fromMessage kept the input's arrays as they came)
  point_cloud_t in;
  in.pattern = format.pattern;
  in.num_rings = format.num_rings;
  in.sweep_duration = static_cast<float>(input.sweep_duration);
  in.num_points = static_cast<int32_t>(input.time_offset.size());
  in.intensity = input.intensity;
  in.time_offset = input.time_offset;
  in.ring = input.ring;
  return toRegisteredScan(r, in, frame);
}

keyframe_t toKeyframe(const Keyframe& k, int16_t num_rings, const OdometryFrame& frame) {
  const KeyframeIncrement increment{k.relative_to_id, k.relative_covariance, k.relative_covariance_held_calibration};
  return keyframeMessage(k.id, k.utime, k.pose, k.pose_covariance, increment, k.cloud, k.intensity, num_rings,
                         OutputFrame{frame.epoch, frame.correction_id});
}

filter_state_t toStatePrior(const LioEstimator& lio, int64_t utime, int64_t request_id, const std::string& sender) {
  filter_state_t prior = toFilterState(utime, lio.state(), lio.covariance(), request_id, sender, lio.bodyRate());
  prior.epoch = lio.frame().epoch;
  prior.correction_id = lio.frame().correction_id;
  return prior;
}

}  // namespace livo::lio
