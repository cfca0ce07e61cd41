#include "livo/output_messages.hpp"

#include <cmath>

#include "livo/messages.hpp"
#include "livo/time.hpp"

namespace livo {

registered_scan_t registeredScanMessage(int64_t utime, int64_t sweep_start_utime, const Pose3& pose,
                                        const std::vector<Vec3>& world_points, const std::vector<uint32_t>& input_index,
                                        const point_cloud_t& in, const OutputFrame& frame) {
  registered_scan_t m;
  m.utime = utime;
  m.epoch = frame.epoch;
  m.correction_id = frame.correction_id;
  poseTo(pose, m.position, m.orientation);
  point_cloud_t& c = m.cloud;
  c.utime = sweep_start_utime;
  c.frame = "W";
  c.pattern = in.pattern;
  c.num_rings = in.num_rings;
  // the input's own value unless it is unusable (a corrupted message): then the span used
  c.sweep_duration = std::isfinite(in.sweep_duration) && in.sweep_duration >= 0.0f
                         ? in.sweep_duration
                         : static_cast<float>(toSeconds(utime - sweep_start_utime));
  const size_t n = world_points.size();
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
    const uint32_t j = input_index[i];
    c.x[i] = static_cast<float>(world_points[i].x());
    c.y[i] = static_cast<float>(world_points[i].y());
    c.z[i] = static_cast<float>(world_points[i].z());
    c.intensity[i] = has_intensity ? in.intensity[j] : 0.0f;
    c.time_offset[i] = in.time_offset[j];
    c.ring[i] = has_ring ? in.ring[j] : int16_t{-1};
  }
  return m;
}

keyframe_t keyframeMessage(int64_t id, int64_t utime, const Pose3& pose, const Mat6& pose_covariance,
                           const KeyframeIncrement& increment, const std::vector<Vec3>& cloud,
                           const std::vector<float>& intensity, int16_t num_rings, const OutputFrame& frame) {
  keyframe_t m;
  m.id = id;
  m.epoch = frame.epoch;
  m.correction_id = frame.correction_id;
  m.utime = utime;
  poseTo(pose, m.position, m.orientation);
  matrixTo<6>(pose_covariance, m.pose_covariance);
  m.relative_to_id = increment.from_id;
  matrixTo<6>(increment.covariance, m.relative_covariance);
  matrixTo<6>(increment.held_calibration, m.relative_covariance_held_calibration);
  point_cloud_t& c = m.cloud;
  c.utime = utime;
  c.frame = "I";
  c.pattern = point_cloud_t::PATTERN_SPINNING;
  c.num_rings = num_rings;
  c.sweep_duration = 0.0f;
  const size_t n = cloud.size();
  c.num_points = static_cast<int32_t>(n);
  c.x.resize(n);
  c.y.resize(n);
  c.z.resize(n);
  c.intensity.resize(n);
  c.time_offset.assign(n, 0.0f);
  c.ring.assign(n, -1);
  for (size_t i = 0; i < n; ++i) {
    c.x[i] = static_cast<float>(cloud[i].x());
    c.y[i] = static_cast<float>(cloud[i].y());
    c.z[i] = static_cast<float>(cloud[i].z());
    c.intensity[i] = i < intensity.size() ? intensity[i] : 0.0f;
  }
  return m;
}

}  // namespace livo
