// Builds the OctoMap from registered scans: each sweep is cut into time slices cast from the
// LiDAR position at the slice's time (interpolated between the previous sweep's end pose and
// this one's), and keeps the keyframes (body-frame clouds) so that after a loop correction the
// map is rebuilt from the corrected keyframe poses, each cloud cast from its LiDAR origin
// T_W_I * T_I_L. A correction that moves no keyframe point by more than rebuild_tolerance from
// where the tree has it leaves the tree as it is (the shifts are measured against the poses of
// the last rebuild, so small corrections cannot add up unnoticed). The keyframe clouds live on
// disk (KeyframeCloudStore, quantised to keyframe_step): memory holds only their poses. With
// keyframe_spacing a keyframe near one already kept is not kept (rebuilds then cost what the area
// costs), and with rebuild_keyframes_per_scan a rebuild is staged: a second tree takes the sweeps
// from the correction on and that many keyframes per sweep, and replaces the map when every kept
// keyframe is in it; a correction during a staged rebuild is taken up by the next one.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "livo/map_inputs.hpp"
#include "livo/octomap/occupancy_map.hpp"
#include "livo/so3.hpp"
#include "livo/spill_file.hpp"

namespace livo::octomap {

struct Keyframe {
  int64_t utime = 0;
  Pose3 T_W_I = Pose3::Identity();      // current (corrected) pose
  std::vector<Eigen::Vector3f> points;  // body frame I
};

class OctomapBuilder {
 public:
  OctomapBuilder(const OctomapOptions& options, const Pose3& T_I_L);
  const Pose3& lidarExtrinsics() const { return T_I_L_; }

  /// False with `error` for a stale or malformed scan (nothing is inserted).
  bool addScan(const RegisteredScanView& scan, std::string* error);
  /// Keeps a keyframe for rebuilds (a later one with the same id replaces it; one within
  /// keyframe_spacing of a kept one is not kept); false (and nothing kept) for a non-finite pose.
  bool addKeyframe(int64_t id, Keyframe keyframe);
  /// Moves the listed keyframes (unknown ids are ignored), the others by `unlisted` (the
  /// correction's transform: keyframes the loop closure had not seen yet), and rebuilds the map
  /// from every kept keyframe (at once, or staged) if a keyframe point now lies more than
  /// rebuild_tolerance from where the tree has it. Returns the number of keyframes that moved.
  int applyCorrection(const std::map<int64_t, Pose3>& corrected, const Pose3& unlisted = Pose3::Identity());
  /// After applyCorrection: the largest shift of a keyframe point (or LiDAR origin) from where the
  /// tree has it, m (an upper bound: |dt| + 2 sin(angle / 2) * reach), and whether it rebuilt.
  double lastCorrectionShift() const { return last_shift_; }
  /// Whether the last correction rebuilt the map (or started a staged rebuild).
  bool lastCorrectionRebuilt() const { return last_rebuilt_; }
  /// A staged rebuild is under way (its tree is not the map yet).
  bool rebuilding() const { return staged_ != nullptr; }
  /// True once after a staged rebuild's tree became the map (the node publishes it then).
  bool takeRebuildFinished() {
    const bool f = staged_finished_;
    staged_finished_ = false;
    return f;
  }
  /// Casts what a staged rebuild has left and makes its tree the map (before the files at exit).
  void finishRebuild();

  OccupancyMap& map() { return map_; }
  const OccupancyMap& map() const { return map_; }
  int64_t scans() const { return scans_; }
  int64_t rebuilds() const { return rebuilds_; }
  /// Keyframes kept for rebuilds, and those not kept (keyframe_spacing).
  size_t keyframes() const { return keyframes_.size(); }
  int64_t keyframesNotKept() const { return not_kept_; }
  /// Bytes of keyframe clouds on disk.
  uint64_t storedKeyframeBytes() const { return clouds_.diskBytes(); }

 private:
  struct StoredKeyframe {
    int64_t utime = 0;
    Pose3 T_W_I = Pose3::Identity();    // current (corrected) pose
    Pose3 in_tree = Pose3::Identity();  // the pose the tree has this keyframe's data at
    double reach = 0.0;                 // farthest point (or the LiDAR origin) from the body origin, m
  };
  void rebuild();
  /// The largest shift of a kept keyframe's point (or LiDAR origin) from where the tree has it.
  double maxShift() const;
  /// Casts a kept keyframe at its current pose into `map` (at its time) and records that pose.
  void castKeyframe(int64_t id, StoredKeyframe* kf, OccupancyMap* map);
  void startStagedRebuild();
  void stepStagedRebuild(int keyframes);
  struct StagedRebuild {
    std::unique_ptr<OccupancyMap> map;
    std::vector<int64_t> pending;  // kept keyframes, in time order
    size_t next = 0;
  };
  OctomapOptions options_;
  Pose3 T_I_L_;
  OccupancyMap map_;
  std::map<int64_t, StoredKeyframe> keyframes_;
  KeyframeCloudStore clouds_;  // body frame I
  double last_shift_ = 0.0;
  bool last_rebuilt_ = false;
  bool have_previous_ = false;
  int64_t previous_utime_ = 0;
  Pose3 previous_pose_ = Pose3::Identity();
  int64_t scans_ = 0, rebuilds_ = 0, not_kept_ = 0;
  std::unique_ptr<StagedRebuild> staged_;
  bool staged_finished_ = false;
};

}  // namespace livo::octomap
