// Options of the livo-lio node, read from a project config: the rig section (channels, IMU noise,
// LiDAR extrinsic and range limits, optional wheel) and the optional lio section (every key
// optional, unknown keys are errors).
#pragma once

#include <iosfwd>
#include <string>

#include "livo/config.hpp"
#include "livo/lio/lio_options.hpp"

namespace livo::lio {

/// LioOptions with `threads` search threads, the rest at their defaults.
inline LioOptions withSearchThreads(int threads) {
  LioOptions o;
  o.search_threads = threads;
  return o;
}

struct LioNodeOptions {
  std::string name = "lio";
  // inputs (rig.channels)
  std::string imu_channel = "IMU";
  std::string lidar_channel = "LIDAR";
  std::string wheel_channel = "WHEEL";
  std::string camera_channel = "CAMERA";  // image times only (camera hand-off)
  std::string state_posterior_channel = "STATE_POSTERIOR";
  std::string loop_correction_channel = "LOOP_CORRECTION";
  // outputs
  std::string odometry_channel = "ODOMETRY";
  std::string registered_scan_channel = "REGISTERED_SCAN";
  std::string keyframe_channel = "KEYFRAME";
  std::string state_prior_channel = "STATE_PRIOR";
  bool publish_registered_scan = true;

  double imu_reorder_window_s = 0.02;  // IMU is handed to the filter this far behind the newest
  double wheel_max_wait_s = 0.2;       // a sweep waits for wheel data past its end at most this long
  // Supervised runs (scripts/run_pipeline.sh --respawn): the odometry epoch and the next keyframe
  // id are kept in this file (written at every keyframe and reset); a restarted lio with
  // `continue_numbering` starts at the next epoch and the next id. Empty: not kept.
  std::string numbering_file;
  bool continue_numbering = false;
  // Where calibration.csv and calibration.yaml go at exit (LioNode::writeCalibrationFiles; "" none)
  std::string output_dir;

  double clock_reset_s = 1.0;  // an IMU stamp this far before the last one resets the node
  double clock_jump_s = 1.0;   // an IMU stamp this far after the newest is a clock jump
  // (either way a jumping stamp is used only once the next sample confirms the new clock: a
  // single corrupted stamp is dropped instead of resetting or stalling the filter)
  // IMU samples beyond a MEMS IMU's range are corrupted, not motion (finite garbage would otherwise
  // be integrated): refused. Defaults: 2000 deg/s and 16 g, the widest common full-scale settings.
  double imu_max_angular_velocity = 35.0;  // rad/s
  double imu_max_acceleration = 160.0;     // m/s^2
  int max_pending_scans = 50;              // sweeps waiting for IMU; older ones are dropped beyond this

  // Camera hand-off (design.md): at each image time publish STATE_PRIOR and adopt the
  // STATE_POSTERIOR that answers it; nothing later than the image is processed meanwhile.
  bool camera_handoff = false;
  double camera_time_offset_s = 0.0;  // rig.camera.time_offset_s: image utime + offset = IMU time
  double camera_rate_hz = 20.0;       // rig.camera.rate_hz: when the next image is due
  double posterior_max_wait_s = 0.1;  // IMU time past an image after which lio goes on without its posterior
  // An image is handed off once a sweep ending at or after it has arrived (so every sweep ending
  // before it is registered first), or once the IMU has run this far past it (the LiDAR is late or
  // gone). At least a sweep period plus the LiDAR driver's latency: a sweep arrives when it ends.
  double image_lidar_wait_s = 0.25;
  // A sweep waits for the images before its end (a camera driver that delivers later than the
  // LiDAR's): until an image has arrived whose successor is due after the sweep end, or the IMU is
  // this far past the end. Only while a VIO listens and the camera is live (an image within 1 s).
  double image_max_wait_s = 0.1;

  LioOptions core = withSearchThreads(2);  // the process shares the registration's searches between
                                           // two threads (lio.search_threads); the core's default is 1
};

/// Reads rig.* (the keys of the rig schema) and lio.* (all optional) into options.
/// Throws ConfigError on malformed values or unknown keys under lio.
LioNodeOptions readLioNodeOptions(const Config& root);

/// Human-readable summary (printed at start-up).
void printOptions(const LioNodeOptions& o, std::ostream& os);

}  // namespace livo::lio
