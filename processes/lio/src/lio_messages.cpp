#include "livo/lio/lio_messages.hpp"

#include <cmath>
#include <map>

#include "livo/correction_frames.hpp"
#include "livo/map_inputs.hpp"
#include "livo/messages.hpp"
#include "livo/time.hpp"

namespace livo::lio {

ImuSample fromMessage(const imu_t& m) {
  ImuSample s;
  s.utime = m.utime;
  s.gyro = vec3From(m.angular_velocity);
  s.accel = vec3From(m.linear_acceleration);
  return s;
}

WheelSample fromMessage(const wheel_odometry_t& m) { return WheelSample{m.utime, m.left_speed, m.right_speed}; }

bool fromMessage(const point_cloud_t& m, LidarScan* scan, std::string* why) {
  const size_t n = static_cast<size_t>(std::max(0, m.num_points));
  if (m.x.size() != n || m.y.size() != n || m.z.size() != n || m.time_offset.size() != n ||
      (!m.intensity.empty() && m.intensity.size() != n)) {
    *why = "point cloud arrays differ from num_points";
    return false;
  }
  if (m.frame != "L") {
    *why = "point cloud in frame '" + m.frame + "', expected 'L'";
    return false;
  }
  scan->utime = m.utime;
  scan->sweep_duration = m.sweep_duration;
  scan->points.resize(n);
  scan->time_offset.assign(m.time_offset.begin(), m.time_offset.end());
  scan->intensity.assign(m.intensity.begin(), m.intensity.end());
  for (size_t i = 0; i < n; ++i) scan->points[i] = Vec3(m.x[i], m.y[i], m.z[i]);
  return true;
}

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
  registered_scan_t m;
  m.utime = r.utime;
  m.epoch = frame.epoch;
  m.correction_id = frame.correction_id;
  poseTo(r.state.pose(), m.position, m.orientation);
  point_cloud_t& c = m.cloud;
  // points undistorted to r.utime (sweep end); cloud.utime is the sweep start so that
  // cloud.utime + time_offset is each point's capture time (IMU clock), as in the input sweep
  c.utime = r.sweep_start_utime;
  c.frame = "W";
  c.pattern = in.pattern;
  c.num_rings = in.num_rings;
  // the input's own value unless it is unusable (a corrupted message): then the span lio used
  c.sweep_duration = std::isfinite(in.sweep_duration) && in.sweep_duration >= 0.0f
                         ? in.sweep_duration
                         : static_cast<float>(toSeconds(r.utime - r.sweep_start_utime));
  const size_t n = r.world_points.size();
  c.num_points = static_cast<int32_t>(n);
  c.x.resize(n);
  c.y.resize(n);
  c.z.resize(n);
  c.intensity.resize(n);
  c.time_offset.resize(n);
  c.ring.resize(n);
  const bool has_ring = in.ring.size() == static_cast<size_t>(in.num_points);
  const bool has_intensity = in.intensity.size() == static_cast<size_t>(in.num_points);
  for (size_t i = 0; i < n; ++i) {
    const uint32_t j = r.input_index[i];
    c.x[i] = static_cast<float>(r.world_points[i].x());
    c.y[i] = static_cast<float>(r.world_points[i].y());
    c.z[i] = static_cast<float>(r.world_points[i].z());
    c.intensity[i] = has_intensity ? in.intensity[j] : 0.0f;
    c.time_offset[i] = in.time_offset[j];
    c.ring[i] = has_ring ? in.ring[j] : int16_t{-1};
  }
  return m;
}

keyframe_t toKeyframe(const Keyframe& k, int16_t num_rings, const OdometryFrame& frame) {
  keyframe_t m;
  m.id = k.id;
  m.epoch = frame.epoch;
  m.correction_id = frame.correction_id;
  m.utime = k.utime;
  poseTo(k.pose, m.position, m.orientation);
  matrixTo<6>(k.pose_covariance, m.pose_covariance);
  point_cloud_t& c = m.cloud;
  c.utime = k.utime;
  c.frame = "I";
  c.pattern = point_cloud_t::PATTERN_SPINNING;
  c.num_rings = num_rings;
  c.sweep_duration = 0.0f;
  const size_t n = k.cloud.size();
  c.num_points = static_cast<int32_t>(n);
  c.x.resize(n);
  c.y.resize(n);
  c.z.resize(n);
  c.intensity.resize(n);
  c.time_offset.assign(n, 0.0f);
  c.ring.assign(n, -1);
  for (size_t i = 0; i < n; ++i) {
    c.x[i] = static_cast<float>(k.cloud[i].x());
    c.y[i] = static_cast<float>(k.cloud[i].y());
    c.z[i] = static_cast<float>(k.cloud[i].z());
    c.intensity[i] = i < k.intensity.size() ? k.intensity[i] : 0.0f;
  }
  return m;
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
