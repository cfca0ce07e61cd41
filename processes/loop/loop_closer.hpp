// The loop-closure core without middleware: a keyframe store (body-frame clouds on disk, their
// coarse features and GICP covariances derived on demand and cached for the most recently used
// keyframes), radius candidates, coarse-to-fine registration and the pose graph, optimised only
// when a loop is accepted.
#pragma once

#include <cstdint>
#include <list>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "coarse_features.hpp"
#include "gicp.hpp"
#include "livo/spill_file.hpp"
#include "loop_registration.hpp"
#include "pose_graph.hpp"

namespace livo::loop {

struct CandidateOptions {
  double search_radius = 12.0;      // m, around the current (corrected) keyframe position
  double exclude_recent_s = 30.0;   // keyframes this recent are not loop candidates
  int max_candidates = 2;           // nearest first
  int cooldown_keyframes = 3;       // after an accepted loop, skip this many keyframes
};

struct LoopCloserOptions {
  CoarseFeatureOptions coarse;
  double fine_voxel_size = 0.4;     // m
  int covariance_neighbors = 10;
  double map_voxel_size = 0.2;      // m, clouds kept for the global map
  /// Keyframes whose coarse features and GICP clouds stay in memory (the newest and the recent
  /// loop candidates); the others are derived again from the stored cloud when a candidate.
  int feature_cache_keyframes = 32;
  std::string spill_directory;      // where the keyframe clouds go ("" : the temp directory)
  CandidateOptions candidates;
  LoopRegistrationOptions registration;
  PoseGraphOptions graph;
  // Odometry edge noise, added to the relative covariance of the keyframes' absolute ones (which,
  // from a filter with a map, barely grow and say little about the increment): a floor plus a part
  // proportional to the distance travelled, the usual drift model of LiDAR odometry (0.5 % and
  // 0.01 deg/m; the old 2 cm / 2 mrad per edge made 1,450 edges of a 300 s drive worth 0.8 m of
  // random walk and let every loop's noise through).
  double odometry_rotation_floor = 2e-4;       // rad
  double odometry_translation_floor = 2e-3;    // m
  double odometry_rotation_per_m = 2e-4;       // rad per metre travelled
  double odometry_translation_per_m = 5e-3;    // m per metre travelled
  double loop_rotation_sigma = 5e-3;         // rad
  double loop_translation_sigma = 5e-2;      // m
  /// The odometry adopts every correction before its next keyframe (livo-lio does, and lockstep
  /// replay guarantees the order): keyframe poses after a correction are in the corrected frame.
  /// The closer then maps them back to its raw odometry chain, so that an odometry edge never
  /// contains a correction. False for an odometry that ignores LOOP_CORRECTION.
  bool odometry_adopts_corrections = true;
};

struct KeyframeInput {
  int64_t id = 0;
  int64_t utime = 0;
  Pose3 pose = Pose3::Identity();    // odometry W_T_I, as published (after the corrections it adopted)
  Mat6 covariance = Mat6::Zero();    // [rotation; position]
  Points cloud;                      // body frame I
};

struct AcceptedLoop {
  int64_t from_id = 0;   // the new keyframe (source)
  int64_t to_id = 0;     // the earlier keyframe (target)
  int64_t from_utime = 0, to_utime = 0;
  Pose3 T_to_from = Pose3::Identity();  // I_to <- I_from
  int coarse_inliers = 0;
  double fitness = 0.0, overlap = 0.0;
};

struct AddResult {
  std::vector<LoopRegistrationResult> attempts;
  std::optional<AcceptedLoop> loop;  // set if a loop was accepted and the graph optimised
};

class LoopCloser {
 public:
  explicit LoopCloser(LoopCloserOptions options = {})
      : options_(std::move(options)), graph_(options_.graph), clouds_(0.0, options_.spill_directory) {}

  /// Adds a keyframe (ids must increase; throws std::invalid_argument otherwise) and searches
  /// for a loop.
  AddResult addKeyframe(const KeyframeInput& input);

  const PoseGraph& graph() const { return graph_; }
  const std::vector<AcceptedLoop>& loops() const { return loops_; }
  /// T_corrected_odom for the newest keyframe: maps the frame its pose was published in onto the
  /// optimised one (identity before the first loop).
  Pose3 correction() const;
  int64_t utime(int64_t id) const { return keyframes_.at(id).utime; }
  /// The keyframe's cloud for the global map (voxel-downsampled, body frame I), from the store.
  Points mapCloud(int64_t id) const;
  size_t size() const { return keyframes_.size(); }
  /// Keyframes whose derived features are in memory now (<= feature_cache_keyframes).
  size_t cachedFeatures() const { return cache_.size(); }
  /// Bytes of keyframe clouds on disk.
  uint64_t storedCloudBytes() const { return clouds_.diskBytes(); }

 private:
  struct Keyframe {
    int64_t utime = 0;
    Pose3 published = Pose3::Identity();  // as received
    Pose3 odometry = Pose3::Identity();   // in the raw odometry frame (no correction adopted)
    Mat6 covariance = Mat6::Zero();
    Mat3 G_R_I = Mat3::Identity();      // roll and pitch: the gravity-aligned frame G of the keyframe
    bool has_keypoints = false;         // its coarse features are not empty
  };
  /// What registration needs of a keyframe, derived from its stored cloud.
  struct Features {
    CoarseFeatures coarse;  // in G
    GicpCloud fine;         // in G
  };
  std::vector<int64_t> candidates(int64_t id) const;
  std::shared_ptr<const Features> deriveFeatures(const Points& cloud_I, const Mat3& G_R_I) const;
  /// The keyframe's features: from the cache, else derived from the stored cloud and cached.
  std::shared_ptr<const Features> features(int64_t id);
  void cacheFeatures(int64_t id, std::shared_ptr<const Features> f);

  LoopCloserOptions options_;
  PoseGraph graph_;
  std::map<int64_t, Keyframe> keyframes_;
  KeyframeCloudStore clouds_;  // body frame I, float as received (lossless: loops do not change)
  std::list<std::pair<int64_t, std::shared_ptr<const Features>>> cache_;  // most recently used first
  std::vector<AcceptedLoop> loops_;
  int64_t keyframes_since_loop_ = 1000000;
  Pose3 adopted_ = Pose3::Identity();  // the odometry's current frame <- raw odometry frame
};

}  // namespace livo::loop
