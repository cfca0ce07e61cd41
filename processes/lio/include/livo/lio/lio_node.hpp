// The livo-lio node: LCM in (IMU, LIDAR, WHEEL, STATE_POSTERIOR, LOOP_CORRECTION), LCM out
// (ODOMETRY, REGISTERED_SCAN, KEYFRAME) around a LioEstimator.
//
// Determinism: inputs are buffered by time and acted on at watermarks, so the output depends only
// on the messages' contents and stamps, never on the interleaving of channels. IMU samples reach
// the filter imu_reorder_window_s behind the newest one; a sweep is processed once the filter has
// an IMU sample past its end (and, with wheels, a wheel reading past its end or wheel_max_wait_s
// of IMU beyond it).
//
// Camera hand-off (options.camera_handoff): image times from CAMERA are events like sweep ends.
// When the IMU passes one and every sweep ending at or before it has been processed (a sweep
// ending at or after it has arrived, or image_lidar_wait_s of IMU beyond it), the filter is
// propagated to it and published on STATE_PRIOR; a sweep ending exactly at an image comes first
// (a camera triggered at the sweep end or start), then the image at the same time. A sweep in turn
// waits for the images before its end (the camera's watermark, image_max_wait_s). Nothing
// later is processed until the STATE_POSTERIOR with that request id has been adopted (valid = 0:
// the prior is kept), or the IMU has run posterior_max_wait_s past the image: then lio goes on
// LiDAR-only and counts the missing answer. While no live node subscribes to STATE_PRIOR (seen
// from their PROGRESS) nothing is handed off and the output is exactly LiDAR-only. Under lockstep
// replay the answer always arrives first (playback waits for the whole pipeline to be quiescent),
// so replays stay identical.
//
// Quiet promises (progress_t.quiet_*, quietWindows()): with every PROGRESS, lio tells lockstep
// playback which IMU samples (stamped before the next event's threshold), images (stamped after
// it, while no sweep waits for one) and wheel readings (up to the end of a sweep that waits for one
// past it, or any) cannot make it publish, in any interleaving, so playback sends them without
// waiting for it.
#pragma once

#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <optional>

#include "livo/lio/calibration_report.hpp"
#include "livo/lio/lio_config.hpp"
#include "livo/lio/lio_messages.hpp"
#include "livo/node.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/sweep_timing.hpp"
#include "livo/time.hpp"

namespace livo::lio {

class LioNode {
 public:
  LioNode(lcm::LCM& lcm, LioNodeOptions options, bool quiet = false);

  Node& node() { return node_; }
  const LioEstimator& estimator() const { return lio_; }
  int64_t sweepsProcessed() const { return sweeps_; }

  /// What became of the camera hand-off's priors.
  struct HandoffCounts {
    int64_t priors = 0;          // STATE_PRIOR published
    int64_t adopted = 0;         // posteriors adopted
    int64_t kept_prior = 0;      // answered valid = 0 (or unusable): the prior was kept
    int64_t missing = 0;         // no answer within posterior_max_wait_s: went on LiDAR-only
    int64_t images_skipped = 0;  // image times not handed off (filter not tracking yet, or already past them)
    int64_t no_vio = 0;          // image times not handed off because no node answers STATE_PRIOR
  };
  const HandoffCounts& handoffCounts() const { return handoff_; }
  /// What became of the sweeps whose odometry was published.
  struct SweepCounts {
    int64_t published = 0;
    int64_t tracked = 0;     // registered against the map (a LiDAR update)
    int64_t predicted = 0;   // the IMU prediction only
    int64_t degenerate = 0;  // ODOMETRY.degenerate: some direction left to the prediction
  };
  const SweepCounts& sweepCounts() const { return sweep_counts_; }
  /// "odometry of N sweeps: T tracked, P predicted without a LiDAR update, D degenerate", printed at exit.
  std::string sweepSummary() const;
  /// "wheel updates: A accepted, R rejected (chi2 gate), N without a reading; scales left
  /// l +/- sl, right r +/- sr (L intervals learnt from, O gated as slip, U unobservable)", or the
  /// calibration being off. Printed every wheel_log_period_s of sensor time and at exit.
  std::string wheelSummary() const;
  /// The sensors' calibration in the filter against the rig's (calibration_report.hpp), "" before
  /// the filter is initialised. Printed every 10 s of sensor time while any is estimated, and at exit.
  std::string calibrationSummary() const;
  /// At exit: output_dir/calibration.csv (the course, a row per second) and calibration.yaml (the
  /// rig as estimated, a config overlay), when output_dir is set and a calibration is estimated.
  void writeCalibrationFiles();
  /// Odometry resets so far (= the current epoch).
  int64_t resets() const { return resets_; }
  const OdometryFrame& frame() const { return lio_.frame(); }

 private:
  /// A sweep waiting for the IMU: decoded on arrival, with what its outputs need of the message.
  struct PendingScan {
    LidarScan scan;
    SweepFormat format;
    SweepTiming timing;  // lio_.sweepTiming(scan), once on arrival
  };
  void onImu(const imu_t& m);
  /// A plausible sample on a confirmed clock: into the buffer (or a reset on a clock step back).
  void acceptImu(const ImuSample& s);
  /// Writes the epoch and the next keyframe id to options_.numbering_file (if set).
  void saveNumbering();
  void onLidar(const point_cloud_t& m);
  void onWheel(const wheel_odometry_t& m);
  void onCamera(const void* data, int size);
  void onPosterior(const filter_state_t& m);
  void onLoopCorrection(const loop_correction_t& m);
  /// Hands IMU (and wheel) to the filter up to the watermarks and processes every ready sweep.
  void advance();
  /// What advance() acts on next (an image hand-off or a sweep), and the IMU stamp the filter's
  /// newest sample must pass before it may (the waits for the LiDAR, the camera and the wheels).
  struct NextEvent {
    enum Kind { kNone, kImage, kSweep } kind = kNone;
    int64_t utime = 0;
    int64_t imu_after = 0;
    int64_t image_wait = 0;  // a sweep: how far imu_after lies past its end for the images' sake
    int64_t wheel_wait = 0;  // ... and for the wheels' (imu_after is the later of both)
  };
  NextEvent nextEvent() const;
  /// The promises in PROGRESS (progress_t.quiet_*): IMU samples, images and wheel readings that
  /// cannot make advance() act, even interleaved.
  std::vector<Node::QuietWindow> quietWindows() const;
  /// What quietWindows() may promise beyond the IMU (the most channels whose floor the filter is not
  /// past), and the lowest threshold of the next event the covered messages can bring about.
  struct Promises {
    bool images = false, sweeps = false, wheels = false;
    int64_t threshold = 0;
    int64_t period = 0;     // between images
    int64_t image_due = 0;  // where the next image is due
  };
  Promises promises(const NextEvent& next) const;
  void process(const PendingScan& p);
  /// Propagates to an image time and publishes the prior (sets pending_).
  void handOff(int64_t utime);
  void resetAll(const std::string& why);
  /// Warns (HEALTH, stderr) "odometry reset to epoch N: why" after the estimator was reset.
  void announceReset(const std::string& why);
  /// Every second of sensor time: a calibration.csv row; every 10 s a log line.
  void reportCalibration(int64_t utime);
  bool estimatesCalibration() const;
  CalibrationEstimate calibrationEstimate() const;

  LioNodeOptions options_;
  Node node_;
  LioEstimator lio_;
  TimeBuffer<ImuSample> imu_;
  TimeBuffer<WheelSample> wheel_;
  TimeBuffer<std::shared_ptr<PendingScan>> scans_;  // keyed by the sweep end (IMU clock)
  int64_t newest_imu_ = 0;
  bool has_imu_ = false;
  std::optional<ImuSample> held_jump_;  // first sample after a clock jump, until the next confirms it
  int64_t fed_imu_ = 0;                 // newest IMU stamp handed to the filter
  bool fed_any_imu_ = false;
  int64_t fed_wheel_ = 0;
  bool fed_any_wheel_ = false;
  int64_t sweeps_ = 0;
  SweepCounts sweep_counts_;
  int64_t last_wheel_log_ = 0;        // IMU time of the last periodic wheel summary
  int64_t last_calibration_log_ = 0;  // ... and of the last calibration.csv row
  int64_t calibration_t0_ = 0;        // the first row's time (its t_s is 0)
  int64_t calibration_rows_ = 0;
  std::string calibration_csv_;  // calibration.csv so far (output_dir)

  struct PendingPrior {
    int64_t request_id;
    int64_t utime;
  };
  TimeBuffer<bool> images_;              // image times (IMU clock) not yet handed off
  int64_t newest_sweep_end_ = -1;        // the LiDAR's watermark: latest end of a sweep received (IMU clock)
  int64_t last_image_ = -1;              // latest image time handed off or skipped (IMU clock)
  int64_t newest_image_ = -1;            // the camera's watermark: latest image time received (IMU clock)
  std::optional<PendingPrior> pending_;  // prior waiting for its posterior
  int64_t next_request_id_ = 1;
  HandoffCounts handoff_;
  int64_t resets_ = 0;
};

}  // namespace livo::lio
