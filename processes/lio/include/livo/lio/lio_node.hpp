// The livo-lio node: LCM in (IMU, LIDAR, WHEEL, STATE_POSTERIOR, LOOP_CORRECTION), LCM out
// (ODOMETRY, REGISTERED_SCAN, KEYFRAME) around a LioEstimator.
//
// Determinism: inputs are buffered by time and acted on at watermarks, so the output depends only
// on the messages' contents and stamps, never on the interleaving of channels. IMU samples reach
// the filter imu_reorder_window_s behind the newest one; a sweep is processed once the filter has
// an IMU sample past its end (and, with wheels, a wheel reading past its end or wheel_max_wait_s
// of IMU beyond it). The camera hand-off (STATE_PRIOR at camera times) belongs to the VIO issue;
// STATE_POSTERIOR is adopted when it refers to the filter's current time.
#pragma once

#include <lcm/lcm-cpp.hpp>
#include <memory>

#include "livo/lio/lio_config.hpp"
#include "livo/lio/lio_messages.hpp"
#include "livo/node.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/time.hpp"

namespace livo::lio {

class LioNode {
 public:
  LioNode(lcm::LCM& lcm, LioNodeOptions options, bool quiet = false);

  Node& node() { return node_; }
  const LioEstimator& estimator() const { return lio_; }
  int64_t sweepsProcessed() const { return sweeps_; }

 private:
  struct PendingScan {
    point_cloud_t msg;
    LidarScan scan;
  };
  void onImu(const imu_t& m);
  void onLidar(const point_cloud_t& m);
  void onWheel(const wheel_odometry_t& m);
  void onPosterior(const filter_state_t& m);
  void onLoopCorrection(const loop_correction_t& m);
  /// Hands IMU (and wheel) to the filter up to the watermarks and processes every ready sweep.
  void advance();
  void process(const PendingScan& p);
  void resetAll(const std::string& why);

  LioNodeOptions opts_;
  Node node_;
  LioEstimator lio_;
  TimeBuffer<ImuSample> imu_;
  TimeBuffer<WheelSample> wheel_;
  TimeBuffer<std::shared_ptr<PendingScan>> scans_;  // keyed by the sweep end (IMU clock)
  int64_t newest_imu_ = 0;
  bool has_imu_ = false;
  int64_t fed_imu_ = 0;       // newest IMU stamp handed to the filter
  bool fed_any_imu_ = false;
  int64_t fed_wheel_ = 0;
  bool fed_any_wheel_ = false;
  int64_t sweeps_ = 0;
};

}  // namespace livo::lio
