// Options of the livo-vio-feature node, read from a project config: the rig (channels, IMU noise,
// the camera and its extrinsic, optional depth image, LiDAR and wheel) and the optional
// `vio_feature:` section (every key optional, unknown keys are errors).
#pragma once

#include <iosfwd>
#include <string>

#include "livo/config.hpp"
#include "livo/vio_feature/vio_feature_options.hpp"

namespace livo::vio_feature {

struct VioFeatureNodeOptions {
  std::string name = "vio_feature";
  // inputs (rig.channels)
  std::string imu_channel = "IMU";
  std::string camera_channel = "CAMERA";
  std::string depth_channel = "DEPTH";
  std::string wheel_channel = "WHEEL";
  // vio_feature.channels
  std::string registered_scan_channel = "REGISTERED_SCAN";  // in: LiDAR depth (livo-lio / livo-lio-graph)
  std::string visual_state_channel = "VISUAL_STATE";        // out: visual_state_t (livo-lio-graph reads it)
  std::string odometry_channel = "VISUAL_ODOMETRY";         // out: the same as odometry_t, for the tools
  // An image waits for what it may use: the IMU past its time, a wheel reading past it, its depth
  // image, a REGISTERED_SCAN ending after (its time - core.lidar_lag_s); each of the last three at
  // most this much IMU beyond its time (a dead sensor or process must not stall the visual subsystem).
  double wheel_max_wait_s = 0.1;
  double depth_max_wait_s = 0.1;
  double lidar_max_wait_s = 0.3;
  VioFeatureOptions core;  // the estimator's (the camera, the depth sources, front and back end)
};

VioFeatureNodeOptions readVioFeatureNodeOptions(const Config& root);

/// The channels and options, for the log at start-up.
void printOptions(const VioFeatureNodeOptions& o, std::ostream& os);

}  // namespace livo::vio_feature
