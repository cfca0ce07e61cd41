// The odometry processes' point outputs as messages, built the same way by livo-lio and
// livo-lio-graph: REGISTERED_SCAN (the deskewed sweep in the world) and KEYFRAME (a downsampled
// body-frame cloud).
#pragma once

#include <cstdint>
#include <vector>

#include "livo/keyframe_t.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/registered_scan_t.hpp"
#include "livo/so3.hpp"

namespace livo {

/// The frame an odometry output is in (lcmtypes/loop_correction_t.lcm).
struct OutputFrame {
  int32_t epoch = 0;
  int64_t correction_id = 0;
};

/// The undistorted sweep in frame "W": every point is expressed at the sweep end (`utime`, the
/// odometry time), while cloud.utime is the sweep start in the IMU clock and each point keeps its
/// input time_offset, so cloud.utime + time_offset is the point's capture time (what the colouring
/// process uses to pick images). Point i is input point input_index[i]: its intensity, time offset
/// and ring come from `input`, as do the pattern, rings and sweep duration.
registered_scan_t registeredScanMessage(int64_t utime, int64_t sweep_start_utime, const Pose3& pose,
                                        const std::vector<Vec3>& world_points, const std::vector<uint32_t>& input_index,
                                        const point_cloud_t& input, const OutputFrame& frame);

/// The odometry increment a keyframe carries from the previous one (keyframe_t.relative_*).
struct KeyframeIncrement {
  int64_t from_id = -1;                  // the previous keyframe (-1: no increment given)
  Mat6 covariance = Mat6::Zero();        // [rotation; translation in this frame], all of it
  Mat6 held_calibration = Mat6::Zero();  // the part of `covariance` held calibration adds
};

/// A keyframe's body-frame cloud (frame "I", time offsets zero: undistorted to `utime`) and its
/// increment from the previous keyframe.
keyframe_t keyframeMessage(int64_t id, int64_t utime, const Pose3& pose, const Mat6& pose_covariance,
                           const KeyframeIncrement& increment, const std::vector<Vec3>& cloud,
                           const std::vector<float>& intensity, int16_t num_rings, const OutputFrame& frame);

}  // namespace livo
