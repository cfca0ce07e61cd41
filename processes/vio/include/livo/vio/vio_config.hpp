// Options of the livo-vio node, read from a project config: the rig (camera model, extrinsic
// T_I_C, channel, rig.camera.time_offset_s) and the optional `vio:` section (every key optional,
// unknown keys are errors; README.md lists them).
#pragma once

#include <iosfwd>
#include <string>

#include "livo/config.hpp"
#include "livo/sensor_rig.hpp"
#include "livo/vio/grey_image.hpp"
#include "livo/vio/vio_options.hpp"

namespace livo::vio {

struct VioNodeOptions {
  std::string name = "vio";
  // channels
  std::string camera_channel = "CAMERA";  // rig.channels.camera unless vio.channels.camera
  std::string state_prior_channel = "STATE_PRIOR";
  std::string state_posterior_channel = "STATE_POSTERIOR";
  std::string registered_scan_channel = "REGISTERED_SCAN";
  std::string loop_correction_channel = "LOOP_CORRECTION";
  // time
  double camera_time_offset_s = 0.0;  // rig.camera.time_offset_s: image utime + offset = IMU time
  double time_tolerance_s = 0.0005;   // a prior and an image this close in time belong together
  double image_buffer_s = 0.5;        // images without a prior are kept this long behind the newest
  int max_buffered_images = 8;        // ... and at most this many
  ImageCheckOptions image_check;

  CameraRig camera;
  VioOptions core;
};

/// Reads rig.* (through livo::readSensorRig; the rig must have a camera) and vio.*; throws
/// ConfigError on malformed values, values out of range or unknown keys.
VioNodeOptions readVioNodeOptions(const Config& root);

/// Human-readable summary (printed at start-up).
void printOptions(const VioNodeOptions& o, std::ostream& os);

}  // namespace livo::vio
