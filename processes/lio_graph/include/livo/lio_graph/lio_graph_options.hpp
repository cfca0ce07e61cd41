// Options of livo-lio-graph's core (the `lio_graph:` config section and the rig).
#pragma once

#include "livo/imu_initializer.hpp"
#include "livo/imu_preintegration.hpp"
#include "livo/keyframe_selector.hpp"
#include "livo/lio_graph/feature_extraction.hpp"
#include "livo/lio_graph/plane_extraction.hpp"
#include "livo/lio_graph/scan_matching.hpp"
#include "livo/sensor_rig.hpp"
#include "livo/sensor_samples.hpp"
#include "livo/wheel_preintegration.hpp"

namespace livo::lio_graph {

struct LioGraphOptions {
  LidarExtrinsics extrinsics;        // rig.lidar
  double min_range = 1.0;            // m (rig.lidar.min_range, at least features.min_range)
  double max_range = 100.0;          // m
  ImuPreintegrationNoise imu_noise;  // rig.imu
  double gravity = 9.81;             // m/s^2 (rig.imu.gravity)
  ImuInitOptions init;
  FeatureOptions features;
  ScanMatchingOptions matching;

  bool use_wheel = false;  // rig.wheel present and lio_graph.wheel not false
  WheelRig wheel_rig;
  WheelPreintegrationNoise wheel_noise;
  // Cauchy loss on the whitened wheel residual: a slipping wheel (tens of sigmas off the IMU) loses
  // its influence instead of pulling with a bounded one, as a Huber loss would.
  double wheel_cauchy = 3.0;
  double max_wheel_gap_s = 0.2;  // a longer gap between readings: no wheel factor there
  // The tyres' radii over the nominal ([s_l, s_r], wheel_preintegration.hpp) as a parameter of the
  // graph with this prior sigma around 1; 0 keeps them at the nominal.
  double wheel_scale_std = 0.02;

  // Adaptive planar factors (the paper's contribution): planes extracted from every sweep
  // (plane_extraction.hpp) become landmarks of the window, each observation a factor.
  bool planar_factors = true;
  // Only the ground (a level plane below the sensor, plane_extraction.hpp) becomes a landmark. With
  // every plane, patches of curved surfaces (tree crowns overhead, tilted 10-20 deg) joined
  // landmarks they did not fit (residuals up to 70 sigma) and, where the LiDAR says nothing along
  // the road, pulled that direction and the tyre scales away: long_slope diverged on every seed
  // (README, "Measured").
  bool planar_ground_only = true;
  PlaneExtractionOptions planes;
  double plane_cloud_voxel = 0.2;       // m: the sweep is downsampled to this before extraction
  double plane_sigma_angle_deg = 1.0;   // an observed plane's normal
  double plane_sigma_distance = 0.02;   // m, at least; its offset (at least its quality)
  double plane_match_angle_deg = 10.0;  // an observation joins a landmark this close in normal ...
  double plane_match_distance = 0.2;    // ... whose plane passes this close to its centroid (m)

  // The visual subsystem's motion (VISUAL_STATE from livo-vio-feature) for the deskew's translation
  // and the scan-matching guess where it covers the sweep (rotation stays the gyro's).
  bool use_visual_motion = false;
  // ... and, when visual_factor, that motion between consecutive states as a relative-pose factor
  // of the graph with these sigmas. The visual estimate shares the IMU and the wheels with this
  // graph, so its sigmas sit well above what the visual window itself claims (that information
  // would otherwise be counted twice); a Cauchy loss on the whitened residual lets a visual failure
  // go. Off by default: on the simulated ground vehicles it made the estimate worse (README).
  bool visual_factor = false;
  double visual_sigma_rotation_deg = 0.5;
  double visual_sigma_translation = 0.01;        // m, plus ...
  double visual_sigma_translation_ratio = 0.02;  // ... this fraction of the motion's length
  double visual_cauchy = 3.0;
  // The visual motion's metric scale as a parameter of the graph (prior sigma around 1; 0 takes it
  // as it is): a wheeled visual subsystem inherits the tyres' nominal radii, which the LiDAR sees.
  double visual_scale_std = 0.02;

  int window_states = 10;  // sweeps in the fixed-lag smoother
  int solver_iterations = 10;
  KeyframeOptions keyframe;  // a new keyframe (local map, KEYFRAME) after 1 m or 10 deg
  // The local map (LIO-SAM's surrounding keyframes): the newest local_map_keyframes, and of every
  // stored keyframe within local_map_radius the oldest in each local_map_spacing cell, so a place
  // seen before is matched against what was mapped there first, not only against the last metres.
  int local_map_keyframes = 10;
  double local_map_radius = 50.0;  // m
  double local_map_spacing = 2.0;  // m
  double map_edge_voxel = 0.2;     // m
  double map_surface_voxel = 0.4;  // m
  // The scan-matching result as a pose measurement: information = scale * J^T J / sigma^2. The
  // residuals of neighbouring points are far from independent (the map's own noise is shared),
  // so the scale is well below one.
  double lidar_point_sigma = 0.05;  // m
  double lidar_information_scale = 0.05;
  double max_imu_gap_s = 0.5;  // s without IMU: the state is re-initialised
  // Keyframes kept for the local map: the newest local_map_keyframes and the oldest per
  // local_map_spacing cell (so the store grows with the area covered, not the distance); beyond
  // this many the one farthest from the newest goes (a 64-beam sweep's features are about 0.25 MB:
  // 500 bound the store near 125 MB; 1 km of new road fills it).
  size_t max_stored_keyframes = 500;
};

}  // namespace livo::lio_graph
