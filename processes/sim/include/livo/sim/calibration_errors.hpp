// Calibration errors: what separates the rig the user believes (`rig:`, the NOMINAL rig every
// estimator reads) from the TRUE rig the simulator renders with. Extrinsic errors act on the
// sensor side, T_I_X_true = T_I_X_nominal * T_err; a sensor's time offset error e means that a
// message stamped t was measured at IMU time t + e (the sign of rig.camera.time_offset_s). With
// `draw` every configured value is a 1-sigma and the actual error is drawn per component from the
// run's seed. The truth is printed at start-up only; `rig:` is never changed.
#pragma once

#include <cstdint>
#include <string>

#include "livo/sensor_rig.hpp"
#include "livo/so3.hpp"

namespace livo::sim {

/// A small rigid error of one sensor's mounting, applied as T_I_X_nominal * transform().
struct ExtrinsicError {
  Vec3 translation = Vec3::Zero();  // m, in the sensor frame X
  Vec3 rpy_deg = Vec3::Zero();      // deg, R = Rz(yaw) Ry(pitch) Rx(roll)
  Pose3 transform() const;
  bool isZero() const { return translation.isZero(0.0) && rpy_deg.isZero(0.0); }
};

struct CalibrationErrors {
  bool draw = false;  // values are 1-sigmas of per-component draws
  ExtrinsicError lidar, camera, wheel;
  double lidar_time_offset_s = 0.0;  // stamp t was measured at IMU time t + offset
  double camera_time_offset_s = 0.0;
  double wheel_time_offset_s = 0.0;
  bool any() const;
};

/// The rig as mounted: every sensor's T_I_X multiplied on the right by its error. Intrinsics,
/// rates, noise and rig.camera.time_offset_s (the user's belief) are kept.
SensorRig trueRig(const SensorRig& nominal, const CalibrationErrors& errors);

/// A zero-mean normal draw of std `sigma`, from its own random stream named `name`: the same
/// (seed, name) always gives the same value, whatever else is drawn.
double drawError(double sigma, uint64_t seed, const std::string& name);
/// Per component: name + ".x", ".y", ".z".
Vec3 drawError(const Vec3& sigma, uint64_t seed, const std::string& name);

/// Every value of `sigma` replaced by its draw (draw stays true, to say so in the print-out).
CalibrationErrors drawCalibrationErrors(const CalibrationErrors& sigma, uint64_t seed);

}  // namespace livo::sim
