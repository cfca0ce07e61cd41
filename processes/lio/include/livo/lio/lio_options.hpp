// Every option of the LiDAR-inertial odometry, with defaults (filled from YAML by the node).
#pragma once

#include <cstddef>

#include "livo/esikf_update.hpp"
#include "livo/imu_initializer.hpp"
#include "livo/keyframe_selector.hpp"
#include "livo/lio/imu_propagator.hpp"
#include "livo/lio/scan_to_map.hpp"
#include "livo/lio/voxel_map.hpp"
#include "livo/lio/voxel_planes.hpp"
#include "livo/lio/wheel_scale.hpp"
#include "livo/lio/wheel_update.hpp"
#include "livo/sensor_samples.hpp"

namespace livo::lio {

/// Which parts of the sensors' calibration the filter estimates (where the rig states an
/// uncertainty). The defaults are what every platform observes (README, "Calibration in the
/// filter"): the LiDAR's time shift, and the camera's rotation and time shift against the LiDAR;
/// the LiDAR's rotation (unobservable in roll and pitch on a vehicle driving on the flat, and
/// confused with the gyro's scale errors in turns) and the translations are held. A camera part
/// estimated while the LiDAR's is held takes the LiDAR's uncertainty into its prior: it is then
/// the camera against the LiDAR-registered body.
struct CalibrationEstimation {
  bool lidar_rotation = false;
  bool lidar_translation = false;
  bool lidar_time = true;
  bool camera_rotation = true;
  bool camera_translation = false;
  bool camera_time = true;
  // The IMU's scale and axis errors (ImuIntrinsics), where the rig states their 1-sigma
  // (rig.imu.*_scale_std, *_misalignment_std): kBudget takes the gyro's as rate noise (ImuNoise)
  // and as a held calibration of the keyframe increments, the accelerometer's not at all;
  // kConsider carries them beside the filter at the nominal sensor's values (their correlation
  // with the state tracked, Schmidt); kEstimate also corrects them (README, "The IMU's axes").
  enum class ImuAxes { kBudget, kConsider, kEstimate };
  ImuAxes imu_axes = ImuAxes::kBudget;
};

/// The prior 1-sigmas of the LiDAR's and the camera's calibration blocks for what `estimate` says.
void calibrationPrior(const CalibrationStd& lidar, const CalibrationStd& camera, const CalibrationEstimation& estimate,
                      CalibrationStd* lidar_prior, CalibrationStd* camera_prior);

struct LioOptions {
  ImuNoise imu_noise;
  ImuInitOptions init;
  // The sensors' calibration (FilterState::lidar / camera): the rig's values are the filter's prior
  // and its stated uncertainty (rig.*.calibration_std) the prior's 1-sigmas; `calibration` says
  // which parts are estimated (the others are held at the rig's values).
  LidarExtrinsics extrinsics;              // rig.lidar.T_I_L and lidar_time_offset_s
  CalibrationStd lidar_calibration_std;    // rig.lidar.calibration_std
  Pose3 camera_T_I_C = Pose3::Identity();  // rig.camera.T_I_C (carried for livo-vio's image updates)
  CalibrationStd camera_calibration_std;   // rig.camera.calibration_std
  CalibrationEstimation calibration;

  // scan preprocessing
  double min_range = 0.5;        // m
  double max_range = 100.0;      // m
  int point_stride = 1;          // keep every n-th valid point for registration (1: all)
  double scan_voxel_size = 0.5;  // m, downsampling of the scan for registration
  int min_points = 100;          // fewer valid points: no update (prediction only)

  // map and registration
  VoxelMapOptions map;
  VoxelPlanesOptions planes;         // planes that average the range noise (lio.map.planes)
  SeenThroughOptions seen_through;   // points later beams pass through leave the map
  double map_radius = 100.0;         // m, local window kept around the body
  double map_prune_distance = 10.0;  // m travelled between window prunings
  /// What a loop correction does to the local map: rebuild it from the stored keyframes' clouds at
  /// their corrected poses (kRebuild: the odometry registers against the corrected map of a place
  /// it passes again), or move it with the frame (kMove: the map stays the odometry's own and its
  /// increments independent of the graph they feed, but the next pass finds the old discrepancy
  /// again; on the held-out 300 s campus runs it corrected twice as often and ended worse).
  enum class OnLoopCorrection { kMove, kRebuild };
  OnLoopCorrection map_on_loop_correction = OnLoopCorrection::kRebuild;
  ScanToMapOptions matching;
  int search_threads = 1;  // threads sharing the neighbour searches of a registration
                           // (the same result for any number; livo-lio's default: 2)
  EsikfOptions esikf;
  int min_residuals = 30;  // fewer: the update is skipped and flagged degenerate

  // robustness
  double max_imu_gap_s = 0.05;     // larger gaps are bridged and reported
  double reset_imu_gap_s = 1.0;    // larger gaps reset the velocity (soft re-initialisation)
  double gap_rate_std = 1.0;       // rad/s: rotation uncertainty added per second of such a gap
                                   // (the position gets init.moving_vel_std per second)
  double max_position_jump = 5.0;  // m per scan: a larger update step is rejected (the sweep is only predicted)
  double max_imu_backlog_s = 1.0;  // IMU waiting for a sweep beyond this is propagated at once
                                   // (a LiDAR outage must not grow the buffer)
  double reseed_after_s = 1.0;     // no registration for this long (LiDAR outage, lost
                                   // track): the map is re-seeded at the predicted pose

  KeyframeOptions keyframe;
  size_t max_stored_keyframes = 300;  // keyframe clouds kept for map rebuilds (bounded memory)

  WheelOptions wheel;
  WheelScaleOptions wheel_scale;  // online scale calibration (used only with wheel.enabled)
};

}  // namespace livo::lio
