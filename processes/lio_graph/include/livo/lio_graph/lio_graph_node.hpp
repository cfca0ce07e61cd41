// The livo-lio-graph node: IMU, LIDAR (and WHEEL) in; ODOMETRY, REGISTERED_SCAN and KEYFRAME out,
// as livo-lio publishes them, so it can stand in for livo-lio in the pipeline
// (scripts/run_pipeline.sh --swap lio=build/bin/livo-lio-graph). LOOP_CORRECTION is adopted as
// livo-lio adopts it: a correction of the current odometry epoch newer than the adopted one moves
// the estimator when it arrives (between sweeps), and the outputs say which frame they are in
// (epoch, correction_id). An estimator reset (an IMU gap) starts a new epoch.
//
// Determinism: sweeps wait in a queue and are processed once the IMU has passed their end (and,
// with wheels, a wheel reading has, or wheel_max_wait_s of IMU beyond it; with the visual subsystem,
// a VISUAL_STATE has, or visual_max_wait_s of IMU beyond it), so the output depends
// only on the messages' contents and stamps, not on how the channels interleave.
#pragma once

#include <lcm/lcm-cpp.hpp>

#include "livo/imu_t.hpp"
#include "livo/lio_graph/lio_graph_config.hpp"
#include "livo/lio_graph/lio_graph_estimator.hpp"
#include "livo/loop_correction_t.hpp"
#include "livo/node.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/sample_queue.hpp"
#include "livo/sensor_feed.hpp"
#include "livo/sweep_timing.hpp"
#include "livo/visual_state_t.hpp"
#include "livo/wheel_odometry_t.hpp"

namespace livo::lio_graph {

class LioGraphNode {
 public:
  LioGraphNode(lcm::LCM& lcm, NodeOptions node_options, LioGraphNodeOptions options);
  Node& node() { return node_; }
  const LioGraphEstimator& estimator() const { return estimator_; }
  const OdometryFrame& frame() const { return estimator_.frame(); }
  /// Odometry resets so far (= the current epoch).
  int64_t resets() const { return resets_; }
  /// Sweeps processed, tracked, predicted only and degenerate.
  std::string summary() const;

 private:
  struct PendingSweep {
    point_cloud_t msg;
    LidarScan scan;
    SweepTiming timing;  // estimator_.sweepTiming(scan), once on arrival
  };
  void onImu(const imu_t& m);
  void onWheel(const wheel_odometry_t& m);
  void onLidar(const point_cloud_t& m);
  void onLoopCorrection(const loop_correction_t& m);
  void onVisualState(const visual_state_t& m);
  /// Warns (HEALTH, stderr) "odometry reset to epoch N: why: re-initialising" after the estimator
  /// was reset.
  void announceReset(const std::string& why);
  /// Whether a sweep ending at t_end may be processed: the IMU has passed its end and, with wheels
  /// or the visual subsystem, their watermark has too, or the IMU has gone their max wait beyond it.
  bool ready(int64_t t_end) const;
  /// Processes the waiting sweeps, oldest first, as long as they are ready.
  void processReady();
  void process(const PendingSweep& p);

  Node node_;
  LioGraphNodeOptions options_;
  LioGraphEstimator estimator_;
  SampleQueue<PendingSweep> pending_;  // by sweep end, in arrival order
  SensorFeed imu_, wheel_;             // into the estimator; their watermarks
  int64_t processed_ = 0, tracked_ = 0, predicted_ = 0, degenerate_ = 0, visual_ = 0, visual_factors_ = 0;
  int64_t resets_ = 0;
};

}  // namespace livo::lio_graph
