// Builds the OctoMap from registered scans: each sweep is cut into time slices cast from the
// LiDAR position at the slice's time (interpolated between the previous sweep's end pose and
// this one's), and keeps the keyframes (body-frame clouds) so that after a loop correction the
// map is rebuilt from the corrected keyframe poses.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "livo/so3.hpp"
#include "occupancy_map.hpp"

namespace livo {
namespace octomap_export {

struct RegisteredScanView {
  int64_t utime = 0;        // sweep end, the pose's time
  int64_t cloud_utime = 0;  // sweep start
  Pose3 T_W_I = Pose3::Identity();
  int num_points = 0;
  const float* x = nullptr;
  const float* y = nullptr;
  const float* z = nullptr;
  const float* time_offset = nullptr;  // may be null
};

struct Keyframe {
  int64_t utime = 0;
  Pose3 T_W_I = Pose3::Identity();     // current (corrected) pose
  std::vector<Eigen::Vector3f> points;  // body frame I
};

class OctomapBuilder {
 public:
  OctomapBuilder(const OctomapOptions& options, const Pose3& T_I_L);

  /// False with `error` for a stale or malformed scan (nothing is inserted).
  bool addScan(const RegisteredScanView& scan, std::string* error);
  void addKeyframe(int64_t id, Keyframe keyframe);
  /// Moves the listed keyframes and, if any moved, rebuilds the map from every keyframe.
  /// Returns the number that moved.
  int applyCorrection(const std::map<int64_t, Pose3>& corrected);

  OccupancyMap& map() { return map_; }
  const OccupancyMap& map() const { return map_; }
  int64_t scans() const { return scans_; }
  int64_t rebuilds() const { return rebuilds_; }
  size_t keyframes() const { return keyframes_.size(); }

 private:
  void rebuild();
  OctomapOptions options_;
  Pose3 T_I_L_;
  OccupancyMap map_;
  std::map<int64_t, Keyframe> keyframes_;
  bool have_previous_ = false;
  int64_t previous_utime_ = 0;
  Pose3 previous_pose_ = Pose3::Identity();
  int64_t scans_ = 0, rebuilds_ = 0;
};

}  // namespace octomap_export
}  // namespace livo
