// IMU units as the log wants them (m/s^2, rad/s). Some drivers publish acceleration in g (Livox
// built-in IMUs) or rates in deg/s. With accel unit "auto" the first samples decide: a median
// |a| near 1 means g (converted, and said in a note), near 9.8 means m/s^2.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "livo/import/import_report.hpp"
#include "livo/imu_t.hpp"

namespace livo::import {

struct ImuUnitOptions {
  std::string accel = "auto";  // auto, m/s2, g
  std::string gyro = "rad/s";  // rad/s, deg/s
  int samples_to_decide = 200;
};

class ImuUnitNormaliser {
 public:
  using Emit = std::function<void(const imu_t&)>;
  /// `source` names the input in notes. Throws std::invalid_argument for an unknown unit.
  ImuUnitNormaliser(ImuUnitOptions options, std::string source, ImportReport& report, Emit emit);
  void add(const imu_t& sample);
  /// Decides with what was seen (if still undecided) and emits the rest. Call at the end.
  void flush();

 private:
  void decide();
  void emitConverted(imu_t s) const;
  ImuUnitOptions options_;
  std::string source_;
  ImportReport& report_;
  Emit emit_;
  std::vector<imu_t> pending_;
  bool decided_ = false;
  double accel_scale_ = 1.0, gyro_scale_ = 1.0;
};

constexpr double kStandardGravity = 9.80665;  // m/s^2 per g

}  // namespace livo::import
