// LioEstimator: the LiDAR-inertial odometry as one object (KISS-ICP's pipeline facade for the
// ESIKF). Feed IMU samples and wheel readings in time order with addImu()/addWheel(), then each
// sweep with addScan() once IMU data past its end has been added; every sweep returns the
// posterior state, its covariance, the undistorted points in the world frame, the degeneracy
// analysis and, when one is due, a keyframe. No middleware: the LCM node wraps it.
#pragma once

#include <cstdint>
#include <deque>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "livo/lio/degeneracy.hpp"
#include "livo/lio/imu_propagator.hpp"
#include "livo/lio/keyframe_clone.hpp"
#include "livo/lio/lio_options.hpp"
#include "livo/odometry_frame.hpp"
#include "livo/sweep_timing.hpp"

namespace livo::lio {

struct Keyframe {
  int64_t id = 0;
  int64_t utime = 0;                    // IMU clock
  Pose3 pose = Pose3::Identity();       // W_T_I
  Mat6 pose_covariance = Mat6::Zero();  // [rotation; position]
  /// The odometry increment from keyframe relative_to_id (the previous one of the epoch; -1: none,
  /// the first keyframe or the first after an IMU re-initialisation) to this one: covariance of
  /// the right perturbation of T_prev^-1 T_this ([rotation; translation in this frame]), from the
  /// filter's cloned pose (keyframe_clone.hpp), plus what the calibration the filter holds at the
  /// rig's values adds (relative_covariance_held_calibration, heldCalibrationCovariance()).
  int64_t relative_to_id = -1;
  Mat6 relative_covariance = Mat6::Zero();
  Mat6 relative_covariance_held_calibration = Mat6::Zero();
  std::vector<Vec3> cloud;       // body frame I, downsampled
  std::vector<float> intensity;  // one per cloud point, from the input sweep (0 if it had none)
};

struct ScanResult {
  enum class Status {
    kInitializing,    // IMU not initialised yet: no output
    kRejected,        // the sweep was not used (see message): no output
    kMapInitialized,  // first sweep: the map was seeded at the initial pose
    kTracked,         // registered against the map
    kPredicted,       // no usable LiDAR update (too few points or matches): IMU prediction only
  };
  Status status = Status::kRejected;
  std::string message;  // what went wrong or was worked around (empty if nothing)

  int64_t utime = 0;              // end of the sweep, IMU clock: the time of state and points
  int64_t sweep_start_utime = 0;  // start of the sweep, IMU clock (input utime + extrinsic time offset)
  FilterState state;
  StateCovariance covariance = StateCovariance::Zero();
  Vec3 angular_velocity = Vec3::Zero();  // bias-corrected, frame I

  int num_points = 0;                  // valid points of the sweep
  int num_registered = 0;              // after downsampling
  int num_residuals = 0;               // point-to-plane residuals of the last iterate
  size_t map_points_seen_through = 0;  // map points this sweep's beams removed (SeenThroughOptions)
  int iterations = 0;
  bool converged = false;
  DegeneracyReport degeneracy;
  double min_information_eigenvalue = 0.0;  // of H^T R^-1 H (6x6)

  // The sweep's valid points, undistorted to utime, in the world frame; input_index[i] is the
  // index of world_points[i] in the input sweep (its intensity, time offset and ring are there).
  std::vector<Vec3> world_points;
  std::vector<uint32_t> input_index;

  bool is_keyframe = false;
  Keyframe keyframe;

  bool hasOutput() const {
    return status == Status::kMapInitialized || status == Status::kTracked || status == Status::kPredicted;
  }
};

const char* toString(ScanResult::Status s);

class LioEstimator {
 public:
  explicit LioEstimator(LioOptions options = {});

  /// Adds an IMU sample (IMU clock). False (with the reason) for non-finite values or a sample
  /// not later than the previous one.
  bool addImu(const ImuSample& s, std::string* why = nullptr);
  /// Adds a wheel reading (IMU clock); used only if options.wheel.enabled.
  bool addWheel(const WheelSample& s, std::string* why = nullptr);
  /// Processes a sweep; IMU samples up to its end should have been added (see scanEndUtime).
  ScanResult addScan(const LidarScan& scan) { return addScan(scan, sweepTiming(scan)); }
  /// The same with the sweep's timing as sweepTiming(scan) gave it (a node times a sweep once, on
  /// arrival, and keeps it while the sweep waits for the IMU).
  ScanResult addScan(const LidarScan& scan, const SweepTiming& timing);

  /// The sweep's start and end in the IMU clock (livo/sweep_timing.hpp, through the rig's LiDAR
  /// time offset); the end is the watermark the IMU must pass before addScan.
  SweepTiming sweepTiming(const LidarScan& scan) const {
    return livo::sweepTiming(scan, options_.extrinsics.time_offset_s);
  }
  /// sweepTiming(scan).end_utime.
  int64_t scanEndUtime(const LidarScan& scan) const { return sweepTiming(scan).end_utime; }

  bool initialized() const { return initialized_; }
  /// Initialised and the map seeded: the state is worth handing to the camera.
  bool tracking() const { return initialized_ && !map_.empty(); }
  /// Time of the filter state (IMU clock).
  int64_t utime() const { return prop_.utime(); }
  /// False for a sweep ending before the filter time, or at it when a sweep already ended there. A
  /// sweep may end exactly where an image hand-off moved the filter (a camera triggered by the LiDAR).
  bool acceptsSweepEnding(int64_t t_end) const {
    return !initialized_ || t_end > prop_.utime() || (t_end == prop_.utime() && t_end != last_sweep_end_utime_);
  }
  const FilterState& state() const { return prop_.state(); }
  const StateCovariance& covariance() const { return prop_.covariance(); }
  /// The bias-corrected angular rate at the filter's time (frame I).
  Vec3 bodyRate() const { return prop_.angularVelocity(prop_.lastSample().gyro, prop_.state()); }
  /// The IMU's sensing-axis errors as estimated (ImuIntrinsics), when they are.
  bool modelsImuIntrinsics() const { return prop_.modelsIntrinsics(); }
  bool estimatesImuAxes() const { return options_.calibration.imu_axes == CalibrationEstimation::ImuAxes::kEstimate; }
  const ImuIntrinsics& imuIntrinsics() const { return prop_.intrinsics(); }
  const ImuIntrinsics::Covariance& imuIntrinsicsCovariance() const { return prop_.intrinsicsCovariance(); }
  const VoxelMap& map() const { return map_; }
  const std::deque<Keyframe>& keyframes() const { return keyframes_; }
  const LioOptions& options() const { return options_; }
  /// IMU samples waiting for a sweep and IMU steps kept for undistortion (bounded; diagnostics).
  size_t imuBacklog() const { return imu_.size(); }
  size_t undistortionSegments() const { return prop_.segments().size(); }
  /// The stamp of the oldest IMU sample waiting for a sweep (INT64_MAX: none): once a sample
  /// max_imu_backlog_s after it is added, the filter propagates the backlog on its own.
  int64_t oldestQueuedImu() const { return imu_.empty() ? std::numeric_limits<int64_t>::max() : imu_.front().utime; }

  /// Camera hand-off: propagates the filter with the added IMU samples to `utime` (STATE_PRIOR).
  bool propagateTo(int64_t utime, std::string* why = nullptr);
  /// Adopts an external update of the state at the filter's current time (STATE_POSTERIOR).
  bool adoptPosterior(int64_t utime, const FilterState& x, const StateCovariance& P, std::string* why = nullptr);

  // livo/odometry_frame.hpp (livo-lio-graph adopts corrections the same way)
  using KeyframePose = livo::KeyframePose;
  using LoopCorrection = livo::LoopCorrection;
  /// Loop correction: moves the state from the current frame onto C_k (by T_Ck_Cj when the
  /// estimator is in j, by T_Ck_O * T_C_O^-1 when it missed corrections), replaces the poses of
  /// the listed keyframes (the others move likewise) and rebuilds the local map from them. The
  /// caller checks the epoch and that the id is newer than frame().correction_id.
  void applyLoopCorrection(const LoopCorrection& correction, const std::vector<KeyframePose>& corrected);
  const OdometryFrame& frame() const { return frame_; }
  int64_t nextKeyframeId() const { return next_keyframe_id_; }
  /// A restarted process goes on where the previous one left its numbering: it starts in odometry
  /// epoch `epoch` (a new frame: the earlier state and map are gone) with keyframe ids from
  /// `next_keyframe_id`, so consumers never see an id or an epoch twice.
  void continueNumbering(int32_t epoch, int64_t next_keyframe_id);

  /// What became of the wheel velocity updates (kept across resets).
  struct WheelCounts {
    int64_t accepted = 0;    // applied
    int64_t rejected = 0;    // chi-square gated ("wheel speed rejected": slip, or a wrong scale)
    int64_t no_reading = 0;  // no wheel reading around the sweep end
  };
  const WheelCounts& wheelCounts() const { return wheel_counts_; }
  /// The online wheel scale calibration (wheel_scale.hpp), kept across resets (it belongs to the
  /// vehicle, not to an odometry epoch); scales 1, never updated, with options.wheel_scale off.
  const WheelScaleEstimator& wheelScale() const { return wheel_scale_; }

  /// Forgets everything (state, map, keyframes, buffers): the next IMU samples re-initialise in a
  /// new odometry epoch (frame().epoch + 1, no correction).
  void reset();

 private:
  // The stages of addScan, in order: each takes its inputs as arguments and returns its results.
  /// Why a sweep ending at t_end is not processed (kRejected, or kInitializing for a sweep of the
  /// IMU start-up window), in `res`; false if it is processed.
  bool refusesSweep(int64_t t_end, ScanResult* res) const;
  /// Indices of the sweep's usable points (finite, inside the sweep [0, end_offset] and the range
  /// limits).
  std::vector<size_t> validPoints(const LidarScan& scan, double end_offset, std::string* note) const;
  /// The valid points in the body frame at t_end (IMU-propagated motion undistortion through the
  /// state's LiDAR calibration); consumes the propagation segments.
  std::vector<Vec3> undistortToSweepEnd(const LidarScan& scan, const std::vector<size_t>& valid,
                                        const FilterState& at_end, int64_t t_first, int64_t t_end);
  /// After the update: the body points and their registration subset re-expressed through the
  /// posterior's LiDAR calibration (extrinsic and time shift), so that x's pose maps them where the
  /// registration put them; `body_rate` is the bias-corrected rate at the sweep end.
  static void toBodyAtSweepEnd(const SensorCalibration& undistorted_with, const FilterState& x, const Vec3& body_rate,
                               std::vector<Vec3>* body, std::vector<Vec3>* reg);
  /// The first state and covariance of an epoch: the IMU's, with the calibration the last epoch
  /// ended with (or the rig's, with its stated uncertainty).
  FilterState initialState(const ImuInitResult& r) const;
  StateCovariance initialCovariance(const ImuInitResult& r) const;
  /// Wheel speed update at the sweep end; returns whether `travel` holds the wheels' travel since
  /// the wheel-scale anchor.
  bool wheelVelocityStage(int64_t t_end, FilterState* x, StateCovariance* P, WheelTravel* travel, std::string* note);
  /// After reseed_after_s without a registration: drops the map (seeded anew at the prediction).
  void reseedAfterOutage(int64_t t_end, FilterState* x, StateCovariance* P, std::string* note);
  /// Map seeding, registration or prediction only; ends a bridged IMU gap's hypothesis. `reg` was
  /// undistorted through `undistorted_with` (the LiDAR's calibration before any update of this sweep).
  ScanResult::Status lidarStage(const std::vector<Vec3>& reg, size_t num_valid,
                                const SensorCalibration& undistorted_with, const Vec3& body_rate, FilterState* x,
                                StateCovariance* P, ScanResult* res);
  /// The iterated point-to-plane update (and the no-time-passed hypothesis after a bridged gap).
  ScanResult::Status registerSweep(const std::vector<Vec3>& reg, const SensorCalibration& undistorted_with,
                                   const Vec3& body_rate, FilterState* x, StateCovariance* P, ScanResult* res);
  /// Remembers the last registration (re-seeding, velocity after IMU gaps).
  void noteRegistration(ScanResult::Status status, const FilterState& x, int64_t t_end);
  /// The calibration the filter holds at the rig's values, with the rig's stated uncertainty.
  HeldCalibration heldCalibration(const FilterState& x) const;
  /// The gyro reading of the last sample as the nominal sensor would have given it (the wheel
  /// update's input): the corrected rate plus the bias.
  Vec3 nominalGyro(const FilterState& x) const;
  /// A new keyframe from the sweep (kept in the bounded keyframe store).
  Keyframe makeKeyframe(const LidarScan& scan, const std::vector<size_t>& valid, const std::vector<Vec3>& body,
                        const FilterState& x, const StateCovariance& P, int64_t t_end);
  void tryInitialize(std::string* note);
  bool propagateThrough(int64_t t_end, std::string* note);
  /// One IMU sample into the propagation (gaps bridged or soft-reset).
  void stepTo(const ImuSample& s, double* worst_gap, std::string* note);
  /// Propagates IMU that no sweep has claimed for max_imu_backlog_s (bounded memory in outages).
  void drainBacklog(int64_t newest);
  void softReset(const ImuSample& s, double gap_s, std::string* note);
  void widenForGap(double gap_s);
  /// Remembers what a bridged IMU gap did to the state (from `before` to now), so that the next
  /// sweep can also try the hypothesis that no time passed (a clock step, not an outage).
  void noteBridgedGap(const FilterState& before);
  /// Mean of the scale-corrected wheel speeds at utime, and its variance due to the scales.
  bool wheelSpeedAt(int64_t utime, double* speed, double* scale_variance) const;
  /// After the LiDAR update: learns the wheel scales from the travel since the last anchor (a
  /// registered, non-degenerate sweep) and makes this sweep the next anchor if it is one.
  void learnWheelScales(const ScanResult& res, const FilterState& x, const WheelTravel* travel);
  /// A sweep that seeded the map or registered: its registration subset `reg` into the map (and
  /// res->map_points_seen_through), its world points into the voxel planes, the local window pruned.
  void addToMap(const std::vector<Vec3>& reg, const FilterState& x, const std::vector<Vec3>& world, ScanResult* res);
  /// Removes the map points the sweep's beams pass through, then adds the sweep; returns how many
  /// map points were removed.
  size_t insertIntoMap(const std::vector<Vec3>& body, const FilterState& x);
  void pruneMap(const Vec3& position);
  const VoxelPlanes* planesForRegistration() const { return options_.planes.enabled ? &planes_ : nullptr; }

  LioOptions options_;
  ImuPropagator prop_;
  VoxelMap map_;
  VoxelPlanes planes_;  // used by the registration when LioOptions::planes.enabled
  // the registration's neighbour searches beyond the calling thread (null: LioOptions::search_threads
  // is 1); shared by copies of the estimator, which take turns
  std::shared_ptr<WorkerThreads> search_threads_;
  KeyframeSelector keyframe_selector_;
  bool initialized_ = false;
  std::vector<ImuSample> init_window_;
  std::deque<ImuSample> imu_;
  std::deque<WheelSample> wheel_;
  int64_t last_imu_utime_ = 0;
  bool has_imu_ = false;
  int64_t last_wheel_utime_ = 0;
  bool has_wheel_ = false;
  WheelScaleEstimator wheel_scale_;
  WheelCounts wheel_counts_;
  bool has_scale_anchor_ = false;  // the last sweep starts a wheel-scale interval
  Pose3 scale_anchor_pose_ = Pose3::Identity();
  int64_t scale_anchor_utime_ = 0;
  Vec3 last_prune_position_ = Vec3::Zero();
  std::deque<Keyframe> keyframes_;
  KeyframeClone clone_;  // the last keyframe's pose, for the next one's relative covariance
  OdometryFrame frame_;
  int64_t next_keyframe_id_ = 0;
  std::vector<Vec3> last_registered_body_;  // last sweep's downsampled body points (map rebuilds)
  // the calibration an odometry reset carries into the next epoch (it belongs to the rig)
  bool has_kept_calibration_ = false;
  FilterState kept_calibration_;
  StateCovariance kept_calibration_cov_ = StateCovariance::Zero();
  int64_t last_registered_utime_ = 0;  // last sweep that seeded the map or registered
  int64_t last_sweep_end_utime_ = -1;  // last sweep that reached the filter (any outcome)
  bool has_registered_ = false;
  Vec3 last_post_pos_ = Vec3::Zero(), prev_post_pos_ = Vec3::Zero();  // registered positions ...
  int64_t last_post_utime_ = 0, prev_post_utime_ = 0;                 // ... of the last two sweeps
  bool has_last_post_ = false, has_prev_post_ = false;
  // Motion the bridged gaps since the last sweep added: the "no time passed" hypothesis undoes it.
  bool gap_bridged_ = false;
  Mat3 gap_undo_rot_ = Mat3::Identity();  // left factor taking the rotation back across the gaps
  Vec3 gap_undo_pos_ = Vec3::Zero();
  Vec3 gap_undo_vel_ = Vec3::Zero();
};

}  // namespace livo::lio
