// Every option of the LiDAR-inertial odometry, with defaults (filled from YAML by the node).
#pragma once

#include <cstddef>

#include "livo/esikf_update.hpp"
#include "livo/imu_initializer.hpp"
#include "livo/keyframe_selector.hpp"
#include "livo/lio/imu_propagator.hpp"
#include "livo/sensor_samples.hpp"
#include "livo/lio/scan_to_map.hpp"
#include "livo/lio/voxel_map.hpp"
#include "livo/lio/wheel_scale.hpp"
#include "livo/lio/wheel_update.hpp"

namespace livo::lio {

struct LioOptions {
  ImuNoise imu_noise;
  ImuInitOptions init;
  LidarExtrinsics extrinsics;

  // scan preprocessing
  double min_range = 0.5;        // m
  double max_range = 100.0;      // m
  int point_stride = 1;          // keep every n-th valid point for registration (1: all)
  double scan_voxel_size = 0.5;  // m, downsampling of the scan for registration
  int min_points = 100;          // fewer valid points: no update (prediction only)

  // map and registration
  VoxelMapOptions map;
  SeenThroughOptions seen_through;     // points later beams pass through leave the map
  double map_radius = 100.0;           // m, local window kept around the body
  double map_prune_distance = 10.0;    // m travelled between window prunings
  ScanToMapOptions matching;
  int search_threads = 1;              // threads sharing the neighbour searches of a registration
                                       // (the same result for any number; livo-lio's default: 2)
  EsikfOptions esikf;
  int min_residuals = 30;              // fewer: the update is skipped and flagged degenerate

  // robustness
  double max_imu_gap_s = 0.05;         // larger gaps are bridged and reported
  double reset_imu_gap_s = 1.0;        // larger gaps reset the velocity (soft re-initialisation)
  double gap_rate_std = 1.0;           // rad/s: rotation uncertainty added per second of such a gap
                                       // (the position gets init.moving_vel_std per second)
  double max_position_jump = 5.0;      // m per scan: a larger update step is rejected (the sweep is only predicted)
  double max_imu_backlog_s = 1.0;      // IMU waiting for a sweep beyond this is propagated at once
                                       // (a LiDAR outage must not grow the buffer)
  double reseed_after_s = 1.0;         // no registration for this long (LiDAR outage, lost
                                       // track): the map is re-seeded at the predicted pose

  KeyframeOptions keyframe;
  size_t max_stored_keyframes = 300;   // keyframe clouds kept for map rebuilds (bounded memory)

  WheelOptions wheel;
  WheelScaleOptions wheel_scale;  // online scale calibration (used only with wheel.enabled)
};

}  // namespace livo::lio
