// What an input's own metadata says about its sensors, beyond what any message carries: a ROS
// sensor_msgs/CameraInfo, an ASL sensor.yaml (EuRoC), an Ouster metadata JSON, a bag preset. Each
// fact names its source, so a starter rig (starter_rig_config.hpp) can say where a number came from.
#pragma once

#include <array>
#include <optional>
#include <string>

#include "livo/import/ros_messages.hpp"
#include "livo/sensor_rig.hpp"
#include "livo/so3.hpp"

namespace livo::import {

/// A pinhole camera's calibration in the rig's terms (livo::CameraRig).
struct CameraIntrinsics {
  int width = 0, height = 0;  // the size the calibration is for
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  DistortionModel distortion_model = DistortionModel::kRadtan;
  std::array<double, 4> distortion{{0.0, 0.0, 0.0, 0.0}};
  std::string source;  // e.g. "camera_info /camera/camera_info", "cam0/sensor.yaml"
  std::string note;    // what did not fit the rig's four coefficients, "" if everything did
};

/// IMU noise densities (continuous time), as livo::ImuRig holds them.
struct ImuNoise {
  double gyro_noise_density = 0.0, gyro_random_walk = 0.0;
  double accel_noise_density = 0.0, accel_random_walk = 0.0;
  std::string source;
};

/// An extrinsic p_I = T * p_S. `yaml` is the text to write (a preset's own form, e.g.
/// "{translation: [...], rpy_deg: [...]}"); empty: written from T.
struct KnownExtrinsic {
  Pose3 T = Pose3::Identity();
  std::string yaml;
  std::string source;
};

struct InputCalibration {
  std::optional<CameraIntrinsics> camera;
  std::optional<ImuNoise> imu_noise;
  std::optional<KnownExtrinsic> T_I_L, T_I_C;
  std::string lidar_model;  // a model the input names (Ouster prod_line), one of livo::kLidarModels; "" if none
  std::string lidar_model_source;
  std::string calibrated_rig;  // the project's calibrated rig for this dataset (a preset's), "" if none
};

/// The calibration of a CameraInfo message, nullopt for an uncalibrated camera (K[0] == 0, as
/// the message's definition says). plumb_bob / radtan -> radtan (k1 k2 p1 p2; a fifth k3 is
/// dropped and said in `note`), equidistant / fisheye / kannala_brandt -> equidistant (k1..k4);
/// another model (rational_polynomial, ...) keeps its first four coefficients as radtan, said in
/// `note`. Binning and a region of interest are said in `note` too (the intrinsics are the
/// full-resolution ones).
std::optional<CameraIntrinsics> intrinsicsFromCameraInfo(const RosCameraInfo& m, const std::string& topic);

/// The pose `T` as the rig's YAML: {translation: [x, y, z], rpy_deg: [0, 0, 0]} for an identity
/// rotation, else the 16 numbers of the row-major 4x4 matrix (exact).
std::string extrinsicYaml(const Pose3& T);

}  // namespace livo::import
