// A starter rig config (livo-import --rig-out FILE): the project config a log needs, written from
// what the import saw. Filled in: the channels written; the rates measured from the stamps
// (rig_survey.hpp); the LiDAR's model guessed from its rings and time layout (lidar_models.hpp),
// with that model's datasheet range and noise; the camera's size and colour from the images, its
// intrinsics and distortion from the input's calibration (a ROS CameraInfo, an ASL sensor.yaml);
// extrinsics and IMU noise where the input or a preset knows them; and the pipeline sections of
// config/rigs/ templates (lio, vio, loop, colour, octomap; those a process can run with). Every
// value the input could not tell carries a "# REPLACE:" comment saying so and which placeholder
// was used; every other value says where it came from. The file passes every process's
// --check-config as it is (a placeholder is a valid value), so a first run needs no edit.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "livo/import/channel_names.hpp"
#include "livo/import/input_calibration.hpp"
#include "livo/import/rig_survey.hpp"

namespace livo::import {

struct StarterRigInputs {
  std::string format, input, log;  // the import: for the header comment
  std::string preset;              // rosbag preset, "" if none
  ChannelNames channels;           // as written
  std::map<std::string, int64_t> channel_counts;
  SensorSurvey survey;
  InputCalibration calibration;
  std::string lidar_layout;  // the importer's PointCloud2 layout (metadata lidar_point_layout), "" if none
};

/// The config's text (YAML with comments; deterministic: no dates, no paths beyond the inputs').
std::string starterRigConfig(const StarterRigInputs& in);

/// Writes starterRigConfig(in) to `path`; throws std::runtime_error if it cannot.
void writeStarterRigConfig(const std::string& path, const StarterRigInputs& in);

}  // namespace livo::import
