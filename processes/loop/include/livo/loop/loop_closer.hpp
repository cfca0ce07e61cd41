// The loop-closure core without middleware: a keyframe store (the graph nodes' body-frame clouds
// on disk, their coarse features and GICP covariances derived on demand and cached for the most
// recently used nodes; every other keyframe only as an offset from its node), radius candidates,
// coarse-to-fine registration and the pose graph, optimised only when a loop is accepted.
#pragma once

#include <cstdint>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "livo/correction_frames.hpp"
#include "livo/loop/coarse_features.hpp"
#include "livo/loop/gicp.hpp"
#include "livo/loop/loop_consistency.hpp"
#include "livo/loop/loop_information.hpp"
#include "livo/loop/loop_registration.hpp"
#include "livo/loop/pose_graph.hpp"
#include "livo/reason_counts.hpp"
#include "livo/spill_file.hpp"

namespace livo::loop {

struct CandidateOptions {
  double search_radius = 12.0;     // m, around the current (corrected) keyframe position
  double exclude_recent_s = 30.0;  // keyframes this recent are not loop candidates
  int max_candidates = 2;          // nearest first
  int cooldown_keyframes = 3;      // after an accepted loop, skip this many keyframes
};

struct LoopCloserOptions {
  CoarseFeatureOptions coarse;
  double fine_voxel_size = 0.4;  // m
  int covariance_neighbors = 10;
  double map_voxel_size = 0.2;  // m, clouds kept for the global map
  /// Keyframes whose coarse features and GICP clouds (as far as derived) stay in memory (the newest
  /// ones near an older node and the recent loop candidates); the others are derived again from the
  /// stored cloud when needed.
  int feature_cache_keyframes = 32;
  std::string spill_directory;  // where the keyframe clouds go ("" : the temp directory)
  CandidateOptions candidates;
  LoopRegistrationOptions registration;
  PoseGraphOptions graph;
  /// The odometry edges' covariance: (true) the odometry's own, from each keyframe's increment from
  /// the previous one (keyframe_t.relative_covariance: livo-lio's filter with a cloned pose),
  /// composed along the edge; or (false, and for any increment that comes without one) the drift
  /// model below.
  bool odometry_covariance_from_filter = true;
  /// The increments' covariances are used times this (1: as the odometry states them).
  double odometry_covariance_scale = 1.0;
  /// Whether the increments' held-calibration part (keyframe_t.relative_covariance_held_calibration)
  /// is composed with the rest. It is one error for the whole run, not one per increment: the
  /// LiDAR mount's telescopes over a chain ((Ad(T_ab^-1) - I) Ad(X) c for the whole span) and is
  /// the same in a loop's registration, so summing it increment by increment as independent
  /// noise grows without bound what stays bounded (README, "The odometry edges"). false (the
  /// default): the filter's part alone, or the whole covariance for an increment whose held part
  /// leaves none (not finite, or larger than the whole; counted in unusableHeldParts()).
  bool compose_held_calibration = false;
  // The drift model: odometry edge noise added to the relative covariance of the keyframes'
  // absolute ones (which, from a filter with a map, barely grow and say little about the
  // increment): a floor plus a part proportional to the distance travelled, the usual drift model
  // of LiDAR odometry (0.5 % and 0.01 deg/m; the old 2 cm / 2 mrad per edge made 1,450 edges of a
  // 300 s drive worth 0.8 m of random walk and let every loop's noise through). The consistency
  // check below always uses it (a loose model, to refuse only what no drift explains).
  double odometry_rotation_floor = 2e-4;     // rad
  double odometry_translation_floor = 2e-3;  // m
  double odometry_rotation_per_m = 2e-4;     // rad per metre travelled
  double odometry_translation_per_m = 5e-3;  // m per metre travelled
  /// A loop edge's covariance: from its fine registration (GICP's point-to-plane information,
  /// floored and capped per `loop_information`: loop_information.hpp), or (false) the fixed
  /// diagonal below, as before.
  bool registration_information = true;
  LoopInformationOptions loop_information;
  double loop_rotation_sigma = 5e-3;     // rad (registration_information false)
  double loop_translation_sigma = 5e-2;  // m (registration_information false)
  /// A verified loop enters the graph only if it agrees, within the chi-square bound, with the
  /// graph's relative pose of its two keyframes (covariance: the odometry's drift model above over
  /// the odometry's path between them) and with the cycle through the earlier loop nearest to it
  /// (loop_consistency.hpp). Refused loops are counted with their reason.
  bool consistency_check = true;
  double consistency_chi2 = kChi2Six999;  // 6 degrees of freedom, p = 0.999
  /// For tests only (empty in the process): sees, and may change, every registration result of
  /// keyframe `from_id` (source) against node `to_id` (target) before it is judged, e.g. to plant
  /// a false loop. The result's T_target_source is between the levelled frames G of the two.
  std::function<void(int64_t from_id, int64_t to_id, LoopRegistrationResult& result)> registration_hook;
  /// A verified loop that the odometry already satisfies to within these (the new keyframe's pose
  /// in the newest correction against where the loop puts it) is added to the graph but neither
  /// optimised nor published: it
  /// would move the estimate by less than the maps resolve, and every correction costs each
  /// consumer a pass over its map. On a route driven again and again nearly every keyframe closes
  /// a loop; without this gate the soak published a correction every 4 keyframes (2,068 in 30 min)
  /// and re-solved the whole graph each time. The edge still counts in the next optimisation.
  double min_correction_translation = 0.02;  // m
  double min_correction_rotation = 1.75e-3;  // rad (0.1 deg: 5 cm at 30 m range)
  /// ... nor is one whose discrepancy the odometry's own uncertainty explains: the squared
  /// Mahalanobis distance of the loop's T_to_from to the estimate's, with the loop's covariance and
  /// the odometry's over the path between the two keyframes (the increments' covariances carried
  /// to one frame and summed), at most this (6 degrees of freedom; 16.81: p = 0.99). 0: off (the
  /// default: correction_from_optimum below asks the better question; over a long lap the
  /// odometry's covariance grows as large as the drift a loop should remove, and this gate then
  /// let the 30 min soak publish one correction); not applied where an increment came without a
  /// covariance (the drift model is loose by design) nor without odometry_covariance_from_filter.
  double correction_chi2 = 0.0;
  /// ... nor one after which the optimised graph leaves the new keyframe where the odometry has it
  /// (in the newest correction sent) to within min_correction_translation / min_correction_rotation:
  /// the graph is optimised with every loop that passes the gates above, and a correction is
  /// published only if the optimum moves what the consumers hold. The loop's residual says whether
  /// the loop disagrees with the odometry; the optimum says whether, weighed against everything
  /// else the graph knows, that changes the estimate. false: the gates above decide alone.
  bool correction_from_optimum = true;
  /// Reduced pose graph (Johannsson et al., "Temporally scalable visual SLAM using a reduced pose
  /// graph", 2013): where the route passes again, a keyframe within this distance of an older
  /// graph node joins that node instead of becoming a node of its own (registered to it, or, near
  /// the node it already hangs from, by odometry), and the pass adds edges between the old nodes.
  /// The graph, and the cost and memory of a solve, then grow with the area mapped, not with the
  /// time driven. 0: every keyframe is a node.
  double merge_distance = 2.0;  // m
  /// At exit, optimise once more if loops entered the graph since the last correction
  /// (optimizePendingLoops), so the exit files hold the estimate with every accepted loop.
  bool optimize_at_exit = true;
  /// Every graph node's roll and pitch held to the odometry's (PoseGraph::addGravityPrior) to
  /// within this (rad): a LiDAR-inertial odometry knows its attitude to gravity, the loops only
  /// relative to it. 0: no prior.
  double gravity_prior_sigma = 1e-3;
};

struct KeyframeInput {
  int64_t id = 0;
  int64_t utime = 0;
  int32_t epoch = 0;               // odometry epoch (keyframe_t.epoch)
  int64_t correction_id = 0;       // the correction of this closer the pose includes (0: none)
  Pose3 pose = Pose3::Identity();  // odometry W_T_I, as published (in correction correction_id)
  Mat6 covariance = Mat6::Zero();  // [rotation; position]
  /// The odometry increment from keyframe relative_to_id (keyframe_t): covariance of the right
  /// perturbation of T_prev^-1 T_this. Used for the odometry edges when it is from the previous
  /// keyframe of the epoch and positive definite; otherwise the drift model stands in.
  int64_t relative_to_id = -1;
  Mat6 relative_covariance = Mat6::Zero();
  /// The part of relative_covariance the odometry's held calibration adds (keyframe_t; zero where
  /// nothing is held).
  Mat6 relative_covariance_held_calibration = Mat6::Zero();
  Points cloud;  // body frame I
};

struct AcceptedLoop {
  int64_t from_id = 0;  // the new keyframe (source)
  int64_t to_id = 0;    // the earlier keyframe (target)
  int64_t from_utime = 0, to_utime = 0;
  Pose3 T_to_from = Pose3::Identity();  // I_to <- I_from
  int coarse_inliers = 0;
  double fitness = 0.0, overlap = 0.0;
  /// How far the odometry's pose of the new keyframe (in the newest correction sent) is from
  /// where the loop puts it (the older keyframe's pose and T_to_from), before optimising, as
  /// rotation angle (rad) and translation (m): the correction gate's measure.
  double residual_rotation = 0.0, residual_translation = 0.0;
  /// correction_chi2's measure (the squared Mahalanobis distance of the discrepancy above) and the
  /// odometry covariance of the estimate it was measured against (right perturbation; both 0 where
  /// the odometry gave no covariance).
  double correction_chi2 = 0.0;
  Mat6 odometry_covariance = Mat6::Zero();
  /// How far the optimised graph moved the new keyframe from the odometry's pose of it (rotation
  /// angle, rad; translation, m): correction_from_optimum's measure (0 if the graph was not
  /// optimised for this loop).
  double optimum_shift_rotation = 0.0, optimum_shift_translation = 0.0;
  bool corrected = false;  // the graph was optimised and a correction published for it
  /// The new keyframe joined the older one (reduced pose graph): the edge went from the node the
  /// odometry came from to `to_id`, and the residual is that edge's.
  bool merged = false;
  /// Covariance of T_to_from's right perturbation ([rotation; translation in I_from]).
  Mat6 covariance = Mat6::Zero();
};

/// A verified loop the consistency check kept out of the graph.
struct RefusedLoop {
  int64_t from_id = 0, to_id = 0;
  bool merged = false;  // it would have joined keyframe from_id to node to_id
  Pose3 T_to_from = Pose3::Identity();
  std::string against;  // "odometry" (the graph's relative pose) or "loop" (a cycle with an earlier one)
  int64_t against_from_id = -1, against_to_id = -1;  // the earlier loop (against "loop")
  double chi2 = 0.0;                                 // of the check that failed (bound: consistency_chi2)
  double path = 0.0;                                 // m of odometry in the prediction it was checked against
  std::string reason;                                // the above in words
};

/// What a LIO adopts after an accepted loop (loop_correction_t): correction `id` of `epoch`.
struct Correction {
  int64_t id = 0;
  int32_t epoch = 0;
  int64_t previous_id = 0;            // the previous correction of the epoch (0: none)
  Pose3 T_Ck_O = Pose3::Identity();   // raw odometry frame of the epoch -> corrected
  Pose3 T_Ck_Cj = Pose3::Identity();  // previous correction's frame -> corrected
};

struct AddResult {
  std::vector<LoopRegistrationResult> attempts;
  std::optional<AcceptedLoop> loop;      // set if a loop was accepted (added to the graph)
  std::optional<Correction> correction;  // if the loop changed the estimate: the correction to publish
  std::vector<RefusedLoop> refused;      // verified loops the consistency check refused
};

class LoopCloser {
 public:
  explicit LoopCloser(LoopCloserOptions options = {})
      : options_(std::move(options)), graph_(options_.graph), clouds_(0.0, options_.spill_directory) {}

  /// Why a keyframe cannot be added ("" if it can): an id not after the newest, an epoch before
  /// the newest keyframe's, or a pose in a correction this closer did not publish for its epoch.
  std::string problem(const KeyframeInput& input) const;
  /// Adds a keyframe (throws std::invalid_argument if problem() is not empty) and searches for a
  /// loop within its epoch. The pose is taken back to the raw odometry frame of its epoch through
  /// the correction it includes, so an odometry edge holds the raw odometry increment whatever
  /// corrections the odometry adopted before publishing it. The first keyframe of a new epoch
  /// (after an odometry reset) starts a graph segment of its own: no odometry edge to the
  /// previous epoch, held fixed in its raw pose; loops are searched only within an epoch.
  AddResult addKeyframe(const KeyframeInput& input);

  /// Optimises the graph if loops entered it since the last optimisation without one (the gate
  /// above): the final estimate with every accepted loop. No correction is published (the odometry
  /// has moved on); keyframes.tum and global_map.ply then hold it. Returns whether it optimised.
  bool optimizePendingLoops();

  /// Graph nodes are a subset of the keyframes (merge_distance); every keyframe has a pose.
  const PoseGraph& graph() const { return graph_; }
  /// A keyframe's corrected pose: its node's, or its node's composed with its offset from it.
  Pose3 pose(int64_t id) const;
  /// Every keyframe, in id order, with its corrected pose.
  void forEachPose(const std::function<void(int64_t id, const Pose3& pose)>& visit) const;
  /// The graph node a keyframe belongs to (its own id if it is one).
  int64_t node(int64_t id) const { return placement(id).node; }
  int64_t newestId() const { return placements_.empty() ? -1 : placements_.back().id; }
  const std::vector<AcceptedLoop>& loops() const { return loops_; }
  const std::vector<RefusedLoop>& refusedLoops() const { return refused_; }
  /// Candidates registered (coarse, then fine if the coarse step passed) and, of them, those the
  /// registration rejected, by the test that did (LoopRegistrationResult::rejected_by).
  int64_t registrations() const { return registrations_; }
  const ReasonCounts& rejectedRegistrations() const { return rejected_registrations_; }
  /// Increments whose held-calibration part could not be taken out of their covariance (it left
  /// no covariance): composed whole instead (compose_held_calibration false).
  int64_t unusableHeldParts() const { return unusable_held_parts_; }
  /// Accepted loops that were optimised and published as a correction.
  size_t corrections() const { return static_cast<size_t>(next_correction_id_ - 1); }
  int64_t utime(int64_t id) const { return placement(id).utime; }
  int32_t epoch(int64_t id) const { return placement(id).epoch; }
  /// Odometry edges whose ends are in different epochs (0 by construction; a check for tests).
  size_t odometryEdgesAcrossEpochs() const;
  /// The keyframe's cloud for the global map (voxel-downsampled, body frame I), from the store.
  Points mapCloud(int64_t id) const;
  size_t size() const { return placements_.size(); }
  /// Keyframes whose derived features are in memory now (<= feature_cache_keyframes).
  size_t cachedFeatures() const { return cache_.size(); }
  /// Bytes of keyframe clouds on disk.
  uint64_t storedCloudBytes() const { return clouds_.diskBytes(); }

 private:
  /// What the closer knows of a keyframe when it arrives, and keeps for graph nodes (registration
  /// targets, the global map) and for the start of the chain the newest keyframe hangs from.
  struct Keyframe {
    int64_t id = -1;
    int64_t utime = 0;
    int32_t epoch = 0;
    Pose3 odometry = Pose3::Identity();  // in the raw odometry frame of its epoch (no correction)
    Mat6 covariance = Mat6::Zero();
    Mat3 G_R_I = Mat3::Identity();  // roll and pitch: the gravity-aligned frame G of the keyframe
    double path = 0.0;              // m of odometry from the first keyframe of its epoch
    /// Covariance of `odometry` given the epoch's first keyframe, as a left perturbation in the
    /// odometry frame: the increments' covariances carried there (Ad(T_k) cov_k Ad(T_k)^T) and
    /// summed, so the odometry's covariance between two keyframes is a difference of two of these.
    Mat6 cumulative_covariance = Mat6::Zero();
    bool cumulative_from_filter = true;  // every increment of it came with the odometry's covariance
    /// Its coarse features are not empty: unknown until a registration with it might be tried
    /// (most keyframes never come near an older node), then kept.
    std::optional<bool> has_keypoints;
  };
  /// What every keyframe keeps (the reduced pose graph's keyframes are mostly not nodes): where it
  /// is relative to its node. About 170 bytes, so a keyframe that joined an older node costs next to
  /// nothing however long the run.
  struct Placement {
    int64_t id = 0;
    int64_t utime = 0;
    int32_t epoch = 0;
    int64_t node = 0;                     // the graph node it belongs to (its own id if it is one)
    Pose3 T_node_kf = Pose3::Identity();  // its pose in that node's frame (identity for a node)
    Vec3 up_in_body = Vec3::UnitZ();      // the odometry's world up axis in its frame (kept)
  };
  /// The odometry's world up axis seen in a keyframe's frame: what its corrected pose keeps.
  static Vec3 upInBody(const Keyframe& kf) { return kf.odometry.linear().transpose() * Vec3::UnitZ(); }
  /// T with the attitude to gravity up_in_body (with the gravity priors on; T itself otherwise).
  Pose3 levelled(const Pose3& T, const Vec3& up_in_body) const;
  Pose3 pose(const Placement& k) const;
  /// Where the newest keyframe hangs from: a graph node, through an optional loop measurement to
  /// keyframe `start`, then raw odometry from `start` on.
  struct Chain {
    int64_t node = -1;
    int64_t start = -1;
    Keyframe start_keyframe;  // the odometry's reference (a node's, or a keyframe that joined one)
    Pose3 T_node_start = Pose3::Identity();
    bool via_loop = false;                // T_node_start is a loop measurement (else start == node)
    double path = 0.0;                    // m of odometry from start
    Mat6 loop_covariance = Mat6::Zero();  // of T_node_start (right perturbation), if via_loop
    /// The raw odometry from start: covariance of the right perturbation of T_start^-1 T_newest,
    /// composed from the increments' own (valid while every increment had one).
    Mat6 odometry_covariance = Mat6::Zero();
    bool filter_covariance = true;
  };
  /// What the consistency check needs of an accepted loop besides AcceptedLoop (parallel to loops_).
  struct LoopAnchor {
    int32_t epoch = 0;
    Pose3 from_odometry = Pose3::Identity();  // raw odometry of the loop's from keyframe
    double from_path = 0.0;
  };
  using FloatCloud = std::vector<Eigen::Vector3f>;
  /// What registration needs of a keyframe, derived from its cloud (body frame, float as stored)
  /// in stages, each when first needed: the coarse keypoints (a registration with the keyframe
  /// might be tried: whether it has coarse features at all), their FPFH descriptors (one is tried:
  /// two thirds of the coarse time), the fine cloud with its kd-tree and covariances (one gets
  /// past the coarse stage: most never do, and it costs more than the coarse features). Each stage
  /// is what deriving everything at once gives: the same floats in, the same computation.
  class Features {
   public:
    Features(const FloatCloud& cloud_I, const Mat3& G_R_I, const LoopCloserOptions& options);
    /// !coarse().points.empty(), without the descriptors if they are not there yet.
    bool hasKeypoints() const;
    const CoarseFeatures& coarse() const;  // in G
    /// In G; `cloud_I` gives the keyframe's cloud again, called only the first time.
    const GicpCloud& fine(const std::function<FloatCloud()>& cloud_I) const;

   private:
    static Points levelled(const FloatCloud& cloud_I, const Mat3& G_R_I);
    CoarseFeatureOptions options_;
    Mat3 G_R_I_;
    double fine_voxel_size_;
    int covariance_neighbors_;
    mutable CoarseKeypoints keypoints_;  // until coarse() describes them
    mutable std::optional<bool> has_keypoints_;
    mutable std::optional<CoarseFeatures> coarse_;
    mutable std::optional<GicpCloud> fine_;
  };
  /// The keyframe being added: what the closer keeps of it, its cloud (float, as keyframe_t carries
  /// it: what later derivations see is what this one sees) and its features once derived.
  struct Arrival {
    Keyframe kf;
    FloatCloud cloud;
    std::shared_ptr<const Features> features;  // derived only when a registration might be tried
  };
  /// The keyframe as the closer keeps it, its pose taken back to the raw odometry frame of its epoch.
  Keyframe arrivingKeyframe(const KeyframeInput& input) const;
  /// A chain that starts at graph node `node` (no loop part).
  static Chain chainFrom(const Keyframe& node);
  /// The odometry's step to the arriving keyframe (and its covariance, if the odometry gave one)
  /// moves the chain on.
  void extendChain(const Pose3& step, const std::optional<Mat6>& step_covariance);
  /// Whether the arriving keyframe has keypoints: derives its features the first time, and notes the
  /// answer in it and in its node if it is one.
  bool hasKeypoints(Arrival& cur);
  /// Places a keyframe that continues its epoch: it joins the chain's node or a near older node, or
  /// becomes a node of its own. Returns whether to go on to the loop search (it became a node and
  /// no registration was tried for it).
  bool placeOnChain(Arrival& cur, AddResult& result);
  /// The nearest older node with keypoints within merge_distance of the odometry's estimate of
  /// the arriving keyframe, if the keyframe has keypoints.
  std::optional<int64_t> nodeToJoin(Arrival& cur, const Pose3& estimate);
  /// Registers the arriving keyframe (graph pose W_T_from) against node to_id: the loop if the
  /// registration verifies it and the consistency check keeps it (the attempt and any refusal are
  /// noted in result and the closer's counts). `merged`: the keyframe would join the node.
  std::optional<AcceptedLoop> verifiedLoop(const Arrival& cur, int64_t to_id, bool merged, const Pose3& W_T_from,
                                           AddResult& result);
  /// The arriving keyframe joins graph node `node` through `loop`; the graph gets the edge from
  /// the chain's node (T_chain_kf: the keyframe in its frame) to `node`, and the chain starts there.
  void joinNode(const Arrival& cur, int64_t node, const Pose3& T_chain_kf, AcceptedLoop loop, AddResult& result);
  /// The arriving keyframe as a node of its own at `estimate`, with the chain's measurement
  /// T_node_kf from the chain's node; the chain starts at it.
  void addChainNode(const Arrival& cur, const Pose3& T_node_kf, const Pose3& estimate);
  /// The loop search of a new node: the older nodes near it with keypoints, nearest first,
  /// registered until one gives a loop that enters the graph.
  void searchLoops(Arrival& cur, AddResult& result);
  const Placement& placement(int64_t id) const;  // throws std::out_of_range for an unknown id
  /// Graph nodes of the keyframe's epoch older than exclude_recent_s within `radius` of p, nearest
  /// first, whether they have keypoints or not (that may take deriving their features).
  std::vector<int64_t> olderNodesNear(int64_t kf_id, const Keyframe& kf, const Vec3& p, double radius) const;
  /// The first `count` of `nodes` that have keypoints (looked at in order, only as far as needed).
  std::vector<int64_t> withKeypoints(const std::vector<int64_t>& nodes, int count);
  /// Whether graph node `id` has keypoints (derived the first time it is asked).
  bool nodeHasKeypoints(int64_t id);
  /// Covariance of the chain's measurement of `to` (the chain's odometry and loop parts), right
  /// perturbation of T_node_to.
  Mat6 chainCovariance(const Keyframe& to) const;
  /// The chain's raw odometry part (start to `to`): the composed increments' covariance if every
  /// increment had one (odometry_covariance_from_filter), else the drift model over the path.
  Mat6 chainOdometryCovariance(const Keyframe& to) const;
  /// The drift model's information of the chain's raw odometry part (start to `to`): the
  /// increment's from the absolute covariances, floored by the drift model over the path.
  Mat6 chainDriftInformation(const Keyframe& to) const;
  /// The increment `step` from the newest keyframe to kf: kf's cumulative covariance from the
  /// newest one's, and the increment's covariance if the input gave a usable one (else nullopt;
  /// the drift model stands in for the cumulative sum).
  std::optional<Mat6> accumulateIncrement(const KeyframeInput& input, const Pose3& step, Keyframe* kf);
  /// The odometry's covariance of T_a^-1 T_b (right perturbation) for two keyframes of an epoch,
  /// if every increment between them came with one (odometry_covariance_from_filter).
  std::optional<Mat6> odometryBetween(const Keyframe& a, const Keyframe& b) const;
  /// A loop's covariance (right perturbation of T_to_from in the body frames) from its registration.
  Mat6 loopCovariance(const LoopRegistrationResult& r, const Keyframe& from) const;
  DriftModel driftModel() const;
  /// Why the loop (from keyframe `from`, whose graph pose is W_T_from) must not enter the graph,
  /// if it must not: the consistency check.
  std::optional<RefusedLoop> inconsistency(const AcceptedLoop& loop, const Keyframe& from, const Pose3& W_T_from) const;
  void accept(const AcceptedLoop& loop, const Keyframe& from, AddResult& result);
  /// Runs the registration of from_id (its cloud: from_cloud) against the graph node to_id (and the
  /// test hook). Both have keypoints.
  /// Keeps a registration among the keyframe's attempts and counts it (registrations()).
  void noteAttempt(const LoopRegistrationResult& r, AddResult& result);
  LoopRegistrationResult registerPair(int64_t from_id, const Features& from, const FloatCloud& from_cloud,
                                      int64_t to_id, const Features& to) const;
  /// Adds a loop edge (if any); unless the odometry already satisfies the loop, optimises and returns the
  /// correction for keyframe `current` (loop gets its residual and `corrected`).
  /// A verified registration of keyframe from_id (source) against to_id (target) as a loop.
  AcceptedLoop acceptedLoop(int64_t from_id, const Keyframe& from, int64_t to_id, const Keyframe& to,
                            const LoopRegistrationResult& r) const;
  std::optional<Correction> addLoopEdge(const PoseEdge* edge, int64_t current, const Keyframe& cur, AcceptedLoop* loop);
  /// Makes keyframe `id` a graph node at `estimate` (its cloud goes to the store).
  void addNode(int64_t id, const Keyframe& kf, const Pose3& estimate, const FloatCloud& cloud);
  /// The keyframe's features: from the cache, else derived from the stored cloud and cached.
  std::shared_ptr<const Features> features(int64_t id);
  void cacheFeatures(int64_t id, std::shared_ptr<const Features> f);

  LoopCloserOptions options_;
  PoseGraph graph_;
  std::vector<Placement> placements_;  // every keyframe, in id order
  std::map<int64_t, Keyframe> nodes_;  // the graph nodes' keyframes
  Keyframe newest_;
  size_t loops_since_optimization_ = 0;  // loop edges added to the graph since it was last optimised // the newest
                                         // keyframe (valid if placements_ is not empty)
  KeyframeCloudStore clouds_;            // the nodes' clouds, body frame I, float as received (lossless)
  std::list<std::pair<int64_t, std::shared_ptr<const Features>>> cache_;  // most recently used first
  std::vector<AcceptedLoop> loops_;
  std::vector<LoopAnchor> anchors_;  // parallel to loops_
  std::vector<RefusedLoop> refused_;
  int64_t registrations_ = 0;
  int64_t unusable_held_parts_ = 0;
  ReasonCounts rejected_registrations_;
  int64_t keyframes_since_loop_ = 1000000;
  CorrectionTable published_;  // the corrections this closer published (T_Ck_O), per epoch
  int64_t next_correction_id_ = 1;
  Chain chain_;
};

}  // namespace livo::loop
