// Options of the livo-vio-feature node, read from a project config: the rig (channels, IMU noise,
// the camera and its extrinsic, optional depth image, LiDAR and wheel) and the optional
// `vio_feature:` section (every key optional, unknown keys are errors).
#pragma once

#include <iosfwd>
#include <string>

#include "livo/config.hpp"
#include "livo/sensor_rig.hpp"
#include "livo/vio_feature/feature_depth.hpp"
#include "livo/vio_feature/feature_tracker.hpp"
#include "livo/vio_feature/vio_feature_options.hpp"

namespace livo::vio_feature {

struct VioFeatureNodeOptions {
  std::string name = "vio_feature";
  CameraRig camera;
  // inputs (rig.channels)
  std::string imu_channel = "IMU";
  std::string camera_channel = "CAMERA";
  std::string depth_channel = "DEPTH";
  std::string wheel_channel = "WHEEL";
  // vio_feature.channels
  std::string registered_scan_channel = "REGISTERED_SCAN";  // in: LiDAR depth (livo-lio / livo-lio-graph)
  std::string visual_state_channel = "VISUAL_STATE";        // out: visual_state_t (livo-lio-graph reads it)
  std::string odometry_channel = "VISUAL_ODOMETRY";          // out: the same as odometry_t, for the tools
  bool use_depth_image = false;   // rig.camera.depth and vio_feature.depth_image not false
  bool use_lidar_depth = false;   // rig.lidar present and vio_feature.lidar_depth not false
  // An image waits for what it may use: the IMU past its time, a wheel reading past it, its depth
  // image, a REGISTERED_SCAN ending after (its time - lidar_lag_s); each of the last three at most
  // this much IMU beyond its time (a dead sensor or process must not stall the visual subsystem).
  double wheel_max_wait_s = 0.1;
  double depth_max_wait_s = 0.1;
  double lidar_max_wait_s = 0.3;
  // An image uses the scans that ended at least this long before it (and waits for one that ended
  // later): livo-lio-graph, coupled, holds a sweep until a visual state past its end exists, so an
  // image must not wait for the sweep around it. More than a sweep's period.
  double lidar_lag_s = 0.15;
  double lidar_depth_window_s = 1.0;  // registered scans this recent lend their points
  FeatureTrackerOptions tracker;
  DepthImageOptions depth_image;
  LidarDepthOptions lidar_depth;
  SlidingWindowOptions window;
};

VioFeatureNodeOptions readVioFeatureNodeOptions(const Config& root);

/// The channels and options, for the log at start-up.
void printOptions(const VioFeatureNodeOptions& o, std::ostream& os);

}  // namespace livo::vio_feature
