// A rig config checked against the log an import wrote (livo-import --rig FILE): what the rig says
// of each sensor against what the messages and the input's calibration show. Errors are what would
// make the run meaningless: the camera's image size (every projection would be wrong), a sensor the
// rig needs missing from the log, a channel the rig reads that the log does not have. Warnings are
// what may be a calibration of another unit or setting: intrinsics and distortion against a
// CameraInfo, rates off by more than 5 %, the LiDAR model's ring count, colour, gravity at rest.
#pragma once

#include <string>
#include <vector>

#include "livo/import/channel_names.hpp"
#include "livo/import/input_calibration.hpp"
#include "livo/import/rig_survey.hpp"
#include "livo/sensor_rig.hpp"

namespace livo::import {

struct RigFinding {
  bool error = false;  // false: a warning
  std::string message;
};

/// Findings, errors first. `rig_file` names the rig in the messages.
std::vector<RigFinding> checkRigAgainstLog(const SensorRig& rig, const std::string& rig_file,
                                           const SensorSurvey& survey, const InputCalibration& calibration,
                                           const ChannelNames& written);

}  // namespace livo::import
