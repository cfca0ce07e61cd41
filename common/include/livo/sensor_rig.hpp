// The sensor rig as mounted (the `rig:` section of a project config): rates, noise, extrinsics,
// intrinsics and channel names. Shared by the simulator and every estimator.
//
//   livo::SensorRig rig = livo::readSensorRig(livo::Config::load(file).section("rig"));
#pragma once

#include <array>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "livo/config.hpp"
#include "livo/so3.hpp"

namespace livo {

struct RigChannels {
  std::string imu = "IMU";
  std::string lidar = "LIDAR";
  std::string camera = "CAMERA";
  std::string depth = "DEPTH";  // depth images registered to the camera (CameraRig::depth)
  std::string wheel = "WHEEL";
  std::string ground_truth = "GROUND_TRUTH";
};

/// Body frame I == IMU frame. Noise parameters are continuous-time densities.
struct ImuRig {
  double rate_hz = 200.0;
  double gyro_noise_density = 1.7e-4;   // rad/s/sqrt(Hz)
  double gyro_random_walk = 1.9e-5;     // rad/s^2/sqrt(Hz)
  double accel_noise_density = 2.0e-3;  // m/s^2/sqrt(Hz)
  double accel_random_walk = 3.0e-3;    // m/s^3/sqrt(Hz)
  double gyro_scale_std = 0.0;          // relative 1-sigma of the gyro's scale factors (datasheet tolerance)
  double gyro_misalignment_std = 0.0;   // rad, 1-sigma of its axis misalignment / cross-axis sensitivity
  double accel_scale_std = 0.0;         // the accelerometer's, likewise
  double accel_misalignment_std = 0.0;  // rad
  double gravity = 9.81;                // m/s^2, world z up
};

/// How well a sensor's calibration is known (1-sigma per axis; 0: exact): the extrinsic's rotation
/// and translation and the time offset. livo-lio estimates what is not exact, with this as the
/// prior (design.md, "Calibration in the filter"). Key `calibration_std` of a lidar or camera; of
/// the wheel, only its rotation (livo-lio-graph and livo-vio-feature estimate the wheel frame's
/// mounting rotation, wheel_preintegration.hpp).
struct CalibrationUncertainty {
  double rotation_deg = 0.0;
  double translation = 0.0;    // m
  double time_offset_s = 0.0;  // s
  bool any() const { return rotation_deg > 0.0 || translation > 0.0 || time_offset_s > 0.0; }
};

struct LidarRig {
  std::string model = "VLP-16";  // one of kLidarModels
  double rate_hz = 10.0;
  double min_range = 0.5;
  double max_range = 100.0;
  double range_noise_std = 0.01;  // m
  double dropout_probability = 0.0;
  Pose3 T_I_L = Pose3::Identity();         // p_I = T_I_L * p_L
  CalibrationUncertainty calibration_std;  // of T_I_L and the LiDAR's time offset (0: exact)
};

/// The lens distortion of a CameraRig, as OpenCV and Kalibr name them.
enum class DistortionModel {
  kRadtan,       // radial-tangential (cv::projectPoints): k1 k2 p1 p2
  kEquidistant,  // Kannala-Brandt (cv::fisheye): theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4
                 // theta^8)
};
/// "radtan" or "equidistant" (the names of the yaml key camera.distortion_model).
const char* distortionModelName(DistortionModel m);

/// Pinhole camera with radial-tangential or equidistant distortion, z forward, x right, y down.
struct CameraRig {
  int width = 640;
  int height = 480;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  DistortionModel distortion_model = DistortionModel::kRadtan;
  std::array<double, 4> distortion{{0.0, 0.0, 0.0, 0.0}};  // radtan: k1 k2 p1 p2; equidistant: k1 k2 k3 k4
  double rate_hz = 20.0;
  bool color = false;                      // RGB8 if true, else GRAY8
  bool depth = false;                      // also a depth image registered to it (same intrinsics, size and
                                           // stamp, as an RGB-D camera's aligned depth), on RigChannels::depth
  Pose3 T_I_C = Pose3::Identity();         // p_I = T_I_C * p_C
  double time_offset_s = 0.0;              // image utime + time_offset_s = the same instant on the IMU clock
  double rolling_shutter_s = 0.0;          // readout time, first to last row (0: global shutter); the
                                           // stamp is the centre row's
  CalibrationUncertainty calibration_std;  // of T_I_C and time_offset_s (0: exact)
};

/// Differential-drive wheel encoder; base frame B: x forward, z up.
struct WheelRig {
  double rate_hz = 50.0;
  double track_width = 0.5;       // m
  double speed_noise_std = 0.02;  // m/s per wheel
  Pose3 T_I_B = Pose3::Identity();
  CalibrationUncertainty calibration_std;  // of T_I_B's rotation only (0: exact, not estimated)

  /// The graphs estimate the mounting rotation where the rig states its uncertainty
  /// (wheel_preintegration.hpp, "Mounting"); its prior sigma per axis, rad.
  bool estimatesMounting() const { return calibration_std.rotation_deg > 0.0; }
  double mountingStdRad() const { return calibration_std.rotation_deg * (M_PI / 180.0); }
};

struct SensorRig {
  RigChannels channels;
  ImuRig imu;
  std::optional<LidarRig> lidar;    // absent: no LiDAR
  std::optional<CameraRig> camera;  // absent: no camera
  std::optional<WheelRig> wheel;    // absent: no wheel encoder
};

/// LiDAR models the rig may name: the five livo-sim has a beam table for (VLP-16, OS1-16, OS1-64,
/// HDL-64E, livox-avia; livo::sim::LidarPattern) and the real sensors of config/rigs/. The
/// estimators read the model only as a label (they use the rate, ranges, noise and T_I_L), so a
/// model here needs no code; the simulator refuses one it cannot simulate.
extern const std::vector<std::string> kLidarModels;

/// Reads and validates a `rig:` section (every key under it must be known); throws ConfigError
/// naming the file and key.
SensorRig readSensorRig(const Config& rig);

/// Human-readable summary (for start-up output).
void printSensorRig(const SensorRig& rig, std::ostream& os);

}  // namespace livo
