#include "livo/lio/lio_messages.hpp"

#include <cmath>
#include <map>

#include "livo/correction_frames.hpp"
#include "livo/map_inputs.hpp"
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
  o.num_residuals = r.num_residuals;
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
  return keyframeMessage(k.id, k.utime, k.pose, k.pose_covariance, k.cloud, k.intensity, num_rings,
                         OutputFrame{frame.epoch, frame.correction_id});
}

bool fromMessage(const loop_correction_t& m, LioEstimator::LoopCorrection* correction,
                 std::vector<LioEstimator::KeyframePose>* poses, std::string* why) {
  std::map<int64_t, Pose3> corrected;
  if (std::string problem = correctedKeyframePoses(m, &corrected); !problem.empty()) {
    *why = "loop correction: " + problem;
    return false;
  }
  if (std::string problem = poseProblem(m.correction_position, m.correction_orientation); !problem.empty()) {
    *why = "loop correction transform: " + problem;
    return false;
  }
  if (std::string problem = correctionTransform(m, &correction->T_Ck_O); !problem.empty()) {
    *why = "loop correction: " + problem;
    return false;
  }
  if (m.previous_correction_id < 0 || m.previous_correction_id >= m.correction_id) {
    *why = "loop correction " + std::to_string(m.correction_id) + ": previous_correction_id " +
           std::to_string(m.previous_correction_id) + " is not before it";
    return false;
  }
  correction->id = m.correction_id;
  correction->previous_id = m.previous_correction_id;
  correction->T_Ck_Cj = poseFrom(m.correction_position, m.correction_orientation);
  poses->clear();
  for (const auto& [id, pose] : corrected) poses->push_back({id, pose});
  return true;
}

}  // namespace livo::lio
