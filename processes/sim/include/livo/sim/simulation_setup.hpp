// Everything one simulation run needs, read once from a project config file: the rig (`rig:`),
// the simulator options (`sim:`), the scene and the trajectory. Only `rig` and `sim` are read.
#pragma once

#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "livo/asl_dataset.hpp"
#include "livo/config.hpp"
#include "livo/sensor_rig.hpp"
#include "livo/sim/calibration_errors.hpp"
#include "livo/sim/camera_renderer.hpp"
#include "livo/sim/depth_effects.hpp"
#include "livo/sim/imu_model.hpp"
#include "livo/sim/lidar_effects.hpp"
#include "livo/sim/lidar_pattern.hpp"
#include "livo/sim/scene.hpp"
#include "livo/sim/trajectory.hpp"
#include "livo/sim/wheel_model.hpp"

namespace livo::sim {

/// The `sim:` options, with their defaults.
/// When the camera exposes (sim.camera.trigger): free-running, its frames halfway between clock
/// ticks, or hardware-triggered by the LiDAR at each sweep's start or end (then at the LiDAR's rate).
enum class CameraTrigger { kFree, kSweepStart, kSweepEnd };

struct SimOptions {
  double start_time_s = 1.7e9;  // stamp of t = 0 (procedural trajectories)
  double duration_s = 30.0;
  double ground_truth_rate_hz = 100.0;
  uint64_t seed = 1;
  int threads = 2;                         // worker threads; the output does not depend on it
  bool images = true;                      // false: no camera or depth images (livo-sim --no-images); every
                                           // other channel is as it is with them (each sensor draws its own noise)
  Vec3 initial_gyro_bias = Vec3::Zero();   // rad/s
  Vec3 initial_accel_bias = Vec3::Zero();  // m/s^2
  LidarPatternOptions lidar;
  LidarEffects lidar_effects;  // sim.lidar receiver effects, all off by default
  CameraEffects camera;
  CameraTrigger camera_trigger = CameraTrigger::kFree;
  DepthEffects depth;             // sim.depth, for a camera with rig.camera.depth
  double wheel_left_scale = 1.0;  // multiplicative scale errors of the wheel speeds
  double wheel_right_scale = 1.0;
  WheelSlipOptions wheel_slip;           // sim.wheel.slip, off by default
  ImuErrors imu_errors;                  // sim.imu error model, as configured (1-sigmas if drawn)
  CalibrationErrors calibration_errors;  // sim.calibration_errors, as configured (1-sigmas if drawn)
};

/// Command-line values that take precedence over the file.
struct SimOverrides {
  std::optional<double> duration_s;
  std::optional<uint64_t> seed;
  std::optional<int> threads;
  bool no_images = false;  // leave the camera's and depth images out
  // Files merged over the config file in order (livo::Config::load's overlays), e.g. a control
  // run with some of the simulator's sensor errors switched off (config/sim/controls/).
  std::vector<std::string> overlays;
};

struct SimulationSetup {
  std::string config_file;  // "FILE + OVERLAY + ..."
  SensorRig rig;
  SimOptions options;
  std::unique_ptr<Scene> scene;
  std::string scene_source;  // file or "inline"
  std::unique_ptr<BodyTrajectory> trajectory;
  std::string trajectory_description;
  int64_t start_utime = 0;
  double trajectory_time_offset = 0.0;     // trajectory time at start_utime
  bool recorded = false;                   // re-simulation along a recording:
  std::vector<AslImuSample> recorded_imu;  //   its real IMU stream, published untouched (none: synthesised)
  // The truth of this run (drawn from the seed when calibration_errors.draw is on): never in `rig`.
  CalibrationErrors calibration_errors;
  ImuErrors imu_errors;

  /// The recording's real IMU samples are published instead of samples synthesised from the motion.
  bool replaysRecordedImu() const { return !recorded_imu.empty(); }
  /// BodyTrajectory time of a stamp.
  double trajectoryTime(int64_t utime) const {
    return static_cast<double>(utime - start_utime) * 1e-6 + trajectory_time_offset;
  }
  int64_t endUtime() const { return start_utime + static_cast<int64_t>(std::llround(options.duration_s * 1e6)); }
};

/// Reads `file` with overrides.overlays merged over it; relative paths inside it are taken from the
/// file's folder. Throws ConfigError
/// (or std::runtime_error for unreadable data files) naming the file and key.
SimulationSetup loadSimulation(const std::string& file, const SimOverrides& overrides = {});
/// Same from a parsed config; `base_dir` resolves relative paths.
SimulationSetup loadSimulation(const Config& root, const std::string& base_dir, const SimOverrides& overrides = {});

void printSimulation(const SimulationSetup& setup, std::ostream& os);

/// The run's truth as JSON (livo-sim --truth): the seed, the calibration errors (extrinsic errors
/// as rotation vectors in the sensor frame, rad, and translations, m: T_I_X_true = T_I_X_rig * T_err;
/// time offset errors, s) and the nominal and true T_I_L / T_I_C (rotation as [w, x, y, z]).
std::string truthJson(const SimulationSetup& setup);

}  // namespace livo::sim
