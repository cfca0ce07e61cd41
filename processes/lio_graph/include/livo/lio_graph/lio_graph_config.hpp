// Options of the livo-lio-graph node, read from a project config: the rig (channels, IMU noise,
// LiDAR extrinsic and range limits, optional wheel) and the optional `lio_graph:` section (every
// key optional, unknown keys are errors).
#pragma once

#include <iosfwd>
#include <string>

#include "livo/config.hpp"
#include "livo/lio_graph/lio_graph_options.hpp"

namespace livo::lio_graph {

struct LioGraphNodeOptions {
  std::string name = "lio_graph";
  // inputs (rig.channels)
  std::string imu_channel = "IMU";
  std::string lidar_channel = "LIDAR";
  std::string wheel_channel = "WHEEL";
  // lio_graph.channels
  std::string odometry_channel = "ODOMETRY";
  std::string registered_scan_channel = "REGISTERED_SCAN";
  std::string keyframe_channel = "KEYFRAME";
  std::string loop_correction_channel = "LOOP_CORRECTION";  // in: adopted as livo-lio adopts it
  std::string visual_state_channel = "VISUAL_STATE";        // in (lio_graph.visual_state: true): livo-vio-feature's
  /// A sweep waits for a wheel reading past its end, or for this much IMU beyond it (a dead
  /// encoder must not stall the odometry).
  double wheel_max_wait_s = 0.1;
  /// With the visual subsystem, a sweep waits for a visual state past its end, or for this much IMU.
  double visual_max_wait_s = 0.2;
  LioGraphOptions core;
};

LioGraphNodeOptions readLioGraphNodeOptions(const Config& root);

/// The channels and options, for the log at start-up.
void printOptions(const LioGraphNodeOptions& o, std::ostream& os);

}  // namespace livo::lio_graph
