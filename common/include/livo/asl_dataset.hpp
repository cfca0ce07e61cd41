// EuRoC / ASL dataset folders (mav0/imu0/data.csv, mav0/cam0/data + sensor.yaml).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "livo/sensor_rig.hpp"
#include "livo/so3.hpp"

namespace livo {

struct AslImuSample {
  int64_t stamp_ns = 0;
  Vec3 gyro = Vec3::Zero();   // rad/s
  Vec3 accel = Vec3::Zero();  // m/s^2
};

/// imu0/data.csv: "#timestamp [ns], w_x, w_y, w_z, a_x, a_y, a_z". Errors name file and line.
std::vector<AslImuSample> readAslImuCsv(const std::string& path);

struct AslImage {
  int64_t stamp_ns = 0;
  std::string path;  // absolute path of the image file
};
/// Images of a camera folder (e.g. mav0/cam0): the files present in data/, stamped by file name
/// (the csv may list more rows than there are images), sorted by time.
std::vector<AslImage> listAslImages(const std::string& camera_dir);

struct AslSensorYaml {
  Pose3 T_body_sensor = Pose3::Identity();  // T_BS
  double rate_hz = 0.0;
  // cameras
  std::vector<double> intrinsics;                               // fu fv cu cv
  DistortionModel distortion_model = DistortionModel::kRadtan;  // distortion_model: radial-tangential
                                                                // (EuRoC) or equidistant (TUM-VI)
  std::vector<double> distortion;                               // radtan: k1 k2 p1 p2; equidistant: k1 k2 k3 k4
  int width = 0, height = 0;
  // IMUs
  double gyro_noise_density = 0.0, gyro_random_walk = 0.0;
  double accel_noise_density = 0.0, accel_random_walk = 0.0;
};
/// Reads an ASL sensor.yaml (the %YAML:1.0 header is accepted). A distortion_model other than
/// radial-tangential (radtan) or equidistant is an error naming the file.
AslSensorYaml readAslSensorYaml(const std::string& path);

/// The camera part of a rig from a camera's sensor.yaml: size, intrinsics, distortion model and
/// coefficients, rate and T_I_C = T_BS (the body being the IMU, as in EuRoC and TUM-VI). Throws
/// TrajectoryError naming `path` if the yaml is not a pinhole camera's (no intrinsics, resolution
/// or four distortion coefficients).
CameraRig aslCameraRig(const AslSensorYaml& s, const std::string& path);

}  // namespace livo
