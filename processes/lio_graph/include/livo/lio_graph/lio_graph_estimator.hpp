// livo-lio-graph's estimator (APGC-LVIW's LiDAR subsystem on LIO-SAM's structure, GTSAM replaced by
// Ceres). Every sweep:
//   1. the IMU is preintegrated from the newest state to the sweep end (Forster et al.), which
//      also predicts the pose at every IMU sample: the sweep is deskewed to its end with them;
//   2. roughness features (edges, surfaces) of the deskewed sweep;
//   3. scan-to-local-map matching from the predicted pose (the LiDAR odometry measurement);
//   4. a new state (pose, velocity, biases) joins a fixed-lag window with an IMU preintegration
//      factor, a bias random walk, the LiDAR pose factor (its information from the matching, so a
//      degenerate direction is left to the other sensors), with wheels a wheel preintegration
//      factor (through the tyres' scales and, where the rig states its uncertainty, the wheel
//      frame's mounting rotation: blocks of the graph for the whole run, never marginalised) and,
//      with the visual subsystem, its motion since the previous state as a relative
//      pose factor; the window is optimised and its oldest state marginalised into a linear prior,
//      so the cost per sweep does not grow with the run;
//   5. every keyframe_distance / keyframe_angle a keyframe: its features enter the local map.
// A LOOP_CORRECTION is adopted as livo-lio adopts it (applyLoopCorrection): the poses are then in
// the corrected frame C_k that frame() names.
// Deterministic: the output depends only on the inputs.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "livo/keyframe_selector.hpp"
#include "livo/lio_graph/lio_graph_options.hpp"
#include "livo/lio_graph/visual_motion.hpp"
#include "livo/marginalization.hpp"
#include "livo/odometry_frame.hpp"
#include "livo/start_state_prior.hpp"
#include "livo/sweep_timing.hpp"

namespace livo::lio_graph {

struct GraphKeyframe {
  int64_t id = 0;
  int64_t utime = 0;
  Pose3 pose = Pose3::Identity();                  // W_T_I
  Mat6 pose_covariance = Mat6::Identity() * 1e-4;  // [rotation, position]
  std::vector<Vec3> cloud;                         // the deskewed sweep, body frame, downsampled
  std::vector<float> intensity;                    // one per cloud point
};

struct GraphScanResult {
  enum class Status { kInitializing, kRejected, kMapInitialized, kTracked, kPredicted };
  Status status = Status::kRejected;
  std::string message;
  int64_t utime = 0;               // sweep end, IMU clock
  int64_t sweep_start_utime = 0;   // IMU clock
  Pose3 pose = Pose3::Identity();  // W_T_I at utime (after the window's optimisation)
  Vec3 velocity = Vec3::Zero();
  Vec3 angular_velocity = Vec3::Zero();  // bias-corrected, frame I
  Vec3 gyro_bias = Vec3::Zero(), accel_bias = Vec3::Zero();
  Vec2 wheel_scale = Vec2::Ones();          // [left, right] tyre radius over the nominal
  Vec3 wheel_mounting = Vec3::Zero();       // the wheel frame's mounting correction δ (rad; wheelMounting())
  Mat6 pose_covariance = Mat6::Identity();  // [rotation (right), position]
  bool degenerate = false;
  bool visual_motion = false;             // the deskew and the guess took the visual subsystem's motion
  bool visual_factor = false;             // and its motion since the previous state joined the graph
  Vec6 weakest_direction = Vec6::Zero();  // of the scan matching, [rotation, translation]
  int edge_residuals = 0, surface_residuals = 0;
  int planes = 0;  // planes observed in the sweep (planar factors)
  int ground_planes = 0;
  int num_points = 0;
  // the sweep's valid points deskewed to utime, world frame, and their indices in the input
  std::vector<Vec3> world_points;
  std::vector<uint32_t> input_index;
  bool is_keyframe = false;
  GraphKeyframe keyframe;
  bool hasOutput() const {
    return status == Status::kMapInitialized || status == Status::kTracked || status == Status::kPredicted;
  }
};

const char* toString(GraphScanResult::Status s);

class LioGraphEstimator {
 public:
  explicit LioGraphEstimator(LioGraphOptions options);
  ~LioGraphEstimator();
  LioGraphEstimator(const LioGraphEstimator&) = delete;
  LioGraphEstimator& operator=(const LioGraphEstimator&) = delete;

  /// False (with the reason) for non-finite values or a sample not later than the previous one.
  bool addImu(const ImuSample& s, std::string* why = nullptr);
  bool addWheel(const WheelSample& s, std::string* why = nullptr);
  /// The visual subsystem's estimate (used when options().use_visual_motion); the same checks.
  bool addVisualState(const VisualSample& s, std::string* why = nullptr);
  /// The newest visual state's time (INT64_MIN before any).
  int64_t visualWatermark() const { return visual_.newest(); }
  /// The sweep's start and end in the IMU clock (livo/sweep_timing.hpp, through the rig's LiDAR
  /// time offset: the same as livo-lio's); the IMU must have passed the end before addScan.
  SweepTiming sweepTiming(const LidarScan& scan) const {
    return livo::sweepTiming(scan, options_.extrinsics.time_offset_s);
  }
  /// sweepTiming(scan).end_utime.
  int64_t scanEndUtime(const LidarScan& scan) const { return sweepTiming(scan).end_utime; }
  GraphScanResult addScan(const LidarScan& scan) { return addScan(scan, sweepTiming(scan)); }
  /// The same with the sweep's timing as sweepTiming(scan) gave it (a node times a sweep once, on
  /// arrival, and keeps it while the sweep waits for the IMU).
  GraphScanResult addScan(const LidarScan& scan, const SweepTiming& timing);

  bool initialized() const { return !window_.empty(); }
  size_t windowSize() const { return window_.size(); }
  size_t planeLandmarks() const { return landmarks_.size(); }
  size_t storedKeyframes() const { return keyframes_.size(); }
  Vec2 wheelScale() const { return Vec2(wheel_scale_[0], wheel_scale_[1]); }
  /// The wheel frame's mounting correction δ (rad): R_IO = R_IB Exp(δ) (wheel_preintegration.hpp),
  /// estimated when estimatesWheelMounting(), else zero (the rig's nominal).
  Vec3 wheelMounting() const { return Vec3(wheel_mounting_[0], wheel_mounting_[1], wheel_mounting_[2]); }
  bool estimatesWheelMounting() const { return options_.use_wheel && options_.wheel_rig.estimatesMounting(); }
  /// What the visual subsystem's translations are multiplied by to be true (estimated).
  double visualScale() const { return visual_scale_[0]; }
  /// Stored keyframe i, oldest first (i < storedKeyframes()).
  const GraphKeyframe& storedKeyframe(size_t i) const { return keyframes_.at(i).kf; }
  const LioGraphOptions& options() const { return options_; }
  const LocalMap& localMap() const { return map_; }
  /// Gravity in the world frame: (0, 0, -gravity) until a loop correction tilts the frame.
  const Vec3& gravity() const { return gravity_W_; }
  /// Forgets everything (state, map, keyframes) but what belongs to the vehicle (the tyre scales,
  /// the wheel mounting: the next epoch's priors are centred on them); the next sweeps initialise
  /// again in a new odometry epoch (frame().epoch + 1, no correction).
  void reset();

  /// Loop correction (lcmtypes/loop_correction_t.lcm), adopted as livo-lio adopts it: everything
  /// moves from the current frame onto C_k by correctionStep() (T_Ck_Cj when the estimator is in
  /// j, T_Ck_O * T_C_O^-1 when it missed corrections): the window's states and plane landmarks,
  /// the factors made from world-frame measurements, the marginal prior and the world gravity (the
  /// correction may tilt the frame). The listed keyframes take their corrected poses, the others
  /// move likewise, and the local map is rebuilt from them. The caller checks the epoch and that
  /// the id is newer than frame().correction_id.
  void applyLoopCorrection(const LoopCorrection& correction, const std::vector<KeyframePose>& corrected);
  const OdometryFrame& frame() const { return frame_; }

 private:
  struct Node;
  struct PlaneLandmark;
  struct ImuStep {
    int64_t utime;
    Pose3 pose;  // predicted W_T_I
  };

  /// The first state from the IMU's start-up window ending at t_end; false (with the reason) while it
  /// cannot start.
  bool initialize(int64_t t_end, std::string* note);
  /// The first state (at rest at the origin, or as the initialisation found it) and its priors; the
  /// accelerometer bias's covariance as the initialisation found it (at rest: tight along "up", where
  /// gravity's magnitude tells the bias, loose across it).
  std::unique_ptr<Node> startNode(int64_t t_end, const FilterState& state, const Vec3& last_gyro,
                                  const StartStateSigmas& sigma, const Mat3& accel_bias_covariance);
  /// The priors of the calibration blocks the window estimates (tyre scales, wheel mounting, visual
  /// scale), around what an earlier epoch learned, added to the first state's.
  void addCalibrationPriors(Node* n);
  /// The IMU preintegration from the newest state to t_end and the predicted poses at every sample.
  bool preintegrate(int64_t t_end, ImuPreintegration* pre, std::vector<ImuStep>* steps, Vec3* last_gyro) const;
  std::unique_ptr<WheelPreintegration> wheelBetween(int64_t t0, int64_t t1) const;
  /// Valid points deskewed to the sweep end, body frame (and their indices).
  void deskew(const LidarScan& scan, int64_t t_first, const std::vector<ImuStep>& steps, std::vector<Vec3>* body,
              std::vector<uint32_t>* index, std::vector<int16_t>* ring, std::vector<float>* time) const;
  /// The visual subsystem's positions at the steps (its motion from the newest state), if it
  /// covers them all.
  std::optional<std::vector<Vec3>> visualPositions(const std::vector<ImuStep>& steps) const;
  /// The roughness features of the deskewed sweep `body` (its rings and times in `cloud`), body frame.
  ScanFeatures bodyFrameFeatures(const std::vector<Vec3>& body, RingCloud cloud) const;
  /// A tracked sweep's state joins the window (matched to the local map from the prediction, or
  /// the visual guess, with its factors), the window is optimised and its oldest states
  /// marginalised; returns the new state.
  Node* addState(int64_t t_end, const ImuPreintegration& pre, const Pose3* visual_guess, const Vec3& last_gyro,
                 const ScanFeatures& features, const std::vector<Vec3>& body, GraphScanResult* res);
  /// The state at t_end the IMU predicts from prev (its pose the visual guess where given).
  std::unique_ptr<Node> predictedState(const Node& prev, int64_t t_end, const ImuPreintegration& pre,
                                       const Pose3* visual_guess, const Vec3& last_gyro) const;
  /// The LiDAR pose factor from a scan match (tracked), or the prediction kept (too few matches).
  void addLidarFactor(const ScanMatchResult& match, Node* n, GraphScanResult* res) const;
  /// The IMU, bias-walk, wheel and visual factors from prev to n.
  void addMotionFactors(const Node& prev, const ImuPreintegration& pre, Node* n, GraphScanResult* res) const;
  /// The newest state, its covariance and the sweep in the world into the result.
  void reportState(const Node& newest, const std::vector<Vec3>& body, GraphScanResult* res);
  /// The sweep as a keyframe: its features join the local map.
  void addKeyframe(const LidarScan& scan, const std::vector<Vec3>& body, ScanFeatures features, const Node* newest,
                   GraphScanResult* res);
  /// Planes of the sweep (body frame) associated with the window's landmarks or new ones; their
  /// factors go to the node.
  void observePlanes(const std::vector<Vec3>& body, Node* node, GraphScanResult* res);
  void optimize();
  void marginalizeOldest();
  void updateKeyframePoses();
  struct StoredKeyframe;
  /// Of the stored keyframes `candidates` (indices, oldest first), the oldest in each
  /// local_map_spacing cell (none when the spacing is 0).
  std::vector<size_t> firstKeyframePerCell(const std::vector<size_t>& candidates) const;
  /// The local map's keyframes around `here`, oldest first (lio_graph_options.hpp).
  std::vector<const StoredKeyframe*> localMapKeyframes(const Vec3& here) const;
  /// Drops the stored keyframes localMapKeyframes() can no longer choose.
  void pruneStoredKeyframes();
  /// The local map from localMapKeyframes(here).
  void rebuildLocalMap(const Vec3& here);
  /// What a loop correction does to a block of the marginal prior (a window state's or landmark's).
  WorldMotion motionOf(const double* block) const;
  Mat6 newestPoseCovariance();
  void dropImuBefore(int64_t utime);
  bool estimatesWheelScale() const { return options_.use_wheel && options_.wheel_scale_std > 0.0; }
  /// The visual relative-pose factor's information for a measured motion T_i_j.
  Mat6 visualInformation(const Pose3& T_i_j) const;
  bool estimatesVisualScale() const {
    return options_.use_visual_motion && options_.visual_factor && options_.visual_scale_std > 0.0;
  }
  /// The parameter blocks of the visual factor that ends at state b.
  std::vector<double*> visualBlocks(Node& a, Node& b);
  /// The parameter blocks of the wheel factor that ends at state b.
  std::vector<double*> wheelBlocks(Node& a, Node& b);

  LioGraphOptions options_;
  VisualMotion visual_;
  std::deque<ImuSample> imu_;
  std::deque<WheelSample> wheel_;
  std::deque<std::unique_ptr<Node>> window_;
  std::deque<std::unique_ptr<PlaneLandmark>> landmarks_;
  std::shared_ptr<MarginalPrior> prior_;
  std::unique_ptr<MarginalPriorFactor> prior_factor_;
  struct StoredKeyframe {
    GraphKeyframe kf;
    std::vector<Vec3> edges, surfaces;  // features, body frame
    const Node* node = nullptr;         // while its state is in the window
  };
  std::deque<StoredKeyframe> keyframes_;
  LocalMap map_;
  KeyframeSelector keyframe_selector_;
  int64_t next_keyframe_id_ = 0;
  int64_t last_sweep_end_ = -1;
  double wheel_scale_[2] = {1.0, 1.0};          // a block of the graph for as long as it runs (never marginalised)
  double wheel_mounting_[3] = {0.0, 0.0, 0.0};  // likewise, the wheel frame's mounting correction δ
  double visual_scale_[1] = {1.0};              // the truth over the visual motion's scale, likewise
  OdometryFrame frame_;
  Vec3 gravity_W_;  // what the IMU factors, the prediction and the plane extraction's "up" use
};

}  // namespace livo::lio_graph
