// Options of livo-vio-feature's core (the `vio_feature:` config section and the rig):
// VioFeatureOptions for VioFeatureEstimator (front end, depth sources, back end), of which
// SlidingWindowOptions is the back end's part.
#pragma once

#include "livo/imu_initializer.hpp"
#include "livo/imu_preintegration.hpp"
#include "livo/sensor_rig.hpp"
#include "livo/so3.hpp"
#include "livo/vio_feature/feature_depth.hpp"
#include "livo/vio_feature/feature_tracker.hpp"
#include "livo/wheel_preintegration.hpp"

namespace livo::vio_feature {

/// The tyre scales' prior sigma where the window has measured depths (livo-lio-graph's).
constexpr double kDepthWheelScaleStd = 0.02;

struct SlidingWindowOptions {
  Pose3 T_I_C = Pose3::Identity();    // rig.camera: p_I = T_I_C p_C
  double camera_time_offset_s = 0.0;  // rig.camera: image utime + offset = the IMU clock
  double focal = 500.0;               // px (rig.camera fx, fy): normalised units to pixels
  ImuPreintegrationNoise imu_noise;   // rig.imu
  double gravity = 9.81;              // m/s^2 (rig.imu.gravity)
  ImuInitOptions init;                // the static start (IMU at rest)
  // The images may say the body is at rest where the IMU cannot (rotor vibration): features
  // moving less than this (median, px) over init.window_s.
  double still_parallax_px = 0.5;

  bool use_wheel = false;  // rig.wheel present and vio_feature.wheel not false
  WheelRig wheel_rig;
  WheelPreintegrationNoise wheel_noise;
  double wheel_cauchy = 3.0;     // Cauchy loss on the whitened wheel residual (slip)
  double max_wheel_gap_s = 0.2;  // a longer gap between readings: no wheel factor there
  // The tyres' radii over the nominal ([s_l, s_r], wheel_preintegration.hpp) as a parameter of the
  // window with this prior sigma around 1 (livo-lio-graph's wheel_scale_std); 0 keeps them at the
  // nominal. Only measured depths make the common scale observable: the node's config sets
  // kDepthWheelScaleStd when a depth source is on and leaves 0 otherwise (monocular, the estimate
  // wanders where the nominal radii are right: README, the window's wheel factor).
  double wheel_scale_std = 0.0;
  // A moving start with the wheel: the body velocity from the wheels, gravity from the specific
  // force over this window minus the acceleration the wheels and the gyro say the body had.
  double moving_init_window_s = 0.5;
  double moving_init_rot_std = 0.03;  // rad, roll and pitch of a moving start

  int window_frames = 10;                // states in the sliding window
  double max_keyframe_interval_s = 1.0;  // a frame this long after the last keyframe is one
  double pixel_sigma = 1.5;              // px, a tracked corner's position
  double reprojection_cauchy = 1.0;      // Cauchy loss scale on the whitened reprojection residual
  // A measured depth's sigma (depth image or LiDAR): base + relative * depth.
  double depth_sigma_base = 0.02;  // m
  double depth_sigma_relative = 0.01;
  double min_depth = 0.2;                    // m: triangulated or measured depths outside are not used
  double max_depth = 80.0;                   // m
  double min_triangulation_angle_deg = 1.0;  // a feature without measured depth waits for this parallax
  int max_features = 200;                    // in the graph per optimisation, longest tracks first
  double outlier_px = 8.0;                   // after an optimisation, a feature this far off in any frame is dropped
  int solver_iterations = 8;
  double max_imu_gap_s = 0.5;  // s without IMU between frames: the estimator restarts
};

/// VioFeatureEstimator's options: everything but the node's channels and waits.
struct VioFeatureOptions {
  CameraRig camera;              // rig.camera
  bool use_depth_image = false;  // rig.camera.depth and vio_feature.depth_image not false
  bool use_lidar_depth = false;  // rig.lidar present and vio_feature.lidar_depth not false
  // An image uses the scans that ended at least this long before it (and the node waits for one
  // that ended later): livo-lio-graph, coupled, holds a sweep until a visual state past its end
  // exists, so an image must not wait for the sweep around it. More than a sweep's period.
  double lidar_lag_s = 0.15;
  double lidar_depth_window_s = 1.0;  // registered scans this recent lend their points
  FeatureTrackerOptions tracker;
  DepthImageOptions depth_image;
  LidarDepthOptions lidar_depth;
  SlidingWindowOptions window;
};

}  // namespace livo::vio_feature
