// The sensors' calibration as the filter has it, against the rig's: for the periodic log line, the
// shutdown summary, calibration.csv (its course) and calibration.yaml (the rig as estimated, a
// config overlay: `scripts/run_pipeline.sh --overlay calibration.yaml` or copied into the rig).
#pragma once

#include <string>

#include "livo/filter_state.hpp"
#include "livo/lio/imu_intrinsics.hpp"

namespace livo::lio {

struct SensorCalibrationChange {
  Vec3 rotation_deg = Vec3::Zero();      // Log(R_rig^T R) in the sensor's frame, deg
  Vec3 translation = Vec3::Zero();       // t - t_rig, m (frame I)
  double time_shift_ms = 0.0;            // the time shift, ms (beyond the rig's offset)
  Vec3 rotation_std_deg = Vec3::Zero();  // the filter's 1-sigmas (0: held fixed)
  Vec3 translation_std = Vec3::Zero();
  double time_shift_std_ms = 0.0;
};

struct CalibrationEstimate {
  SensorCalibrationChange lidar, camera;
  // the camera's rotation against the LiDAR's (R_L_C = R_I_L^T R_I_C), turned from the rig's by
  // Log(R_L_C,rig^T R_L_C) in the camera frame, deg: what the photometric update needs right
  Vec3 camera_lidar_rotation_deg = Vec3::Zero();
};

/// The estimate in x (with its covariance P) against the rig's extrinsics.
CalibrationEstimate calibrationAgainstRig(const FilterState& x, const StateCovariance& P, const Pose3& T_I_L_rig,
                                          const Pose3& T_I_C_rig);

/// One line: "LiDAR rotation (..) deg +/- .., translation (..) mm, time shift .. ms; camera ...".
std::string describe(const CalibrationEstimate& e, bool with_camera);

/// calibration.csv: a header and one row per report (t in s of sensor time).
std::string calibrationCsvHeader();
std::string calibrationCsvRow(double t, const CalibrationEstimate& e);

/// "IMU axes: gyro scale (..) +/- (..) %, off-diagonal (..) +/- (..) mrad; accel ...": the
/// sensing-axis errors as estimated (ImuIntrinsics), with their 1-sigmas.
std::string describeImuIntrinsics(const ImuIntrinsics& k, const ImuIntrinsics::Covariance& P);

/// calibration.yaml: the rig's extrinsics and time offsets as estimated, a config overlay.
std::string calibrationOverlay(const FilterState& x, double lidar_time_offset_rig_s, double camera_time_offset_rig_s,
                               bool with_camera, const CalibrationEstimate& e);

}  // namespace livo::lio
