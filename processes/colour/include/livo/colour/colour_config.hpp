// Reads the `colour:` section of a project config into ColourOptions and node settings (strict:
// unknown keys are errors).
#pragma once

#include <iosfwd>
#include <string>

#include "livo/colour/colour_options.hpp"
#include "livo/config.hpp"
#include "livo/sensor_rig.hpp"

namespace livo::colour {

struct ColourNodeOptions {
  ColourOptions core;
  std::string registered_scan_channel = "REGISTERED_SCAN";
  std::string odometry_channel = "ODOMETRY";
  std::string camera_channel;  // default: the rig's camera channel
  std::string keyframe_channel = "KEYFRAME";
  std::string loop_correction_channel = "LOOP_CORRECTION";
  std::string colored_cloud_channel = "COLORED_CLOUD";
  std::string colour_save_channel = "COLOUR_SAVE";  // any message here writes the map files now
  std::string map_name = "colour_map";              // files <output_dir>/<map_name>.ply / .pcd
  // COLORED_CLOUD is split into messages of at most this many points (~15 bytes each): a loop
  // correction that moves the whole map must not become one message of tens of MB, which a UDP
  // bus loses (design.md, pitfalls).
  int max_points_per_message = 65536;
};

ColourNodeOptions readColourNodeOptions(const Config& root);

/// The rig (`rig:`, livo::readSensorRig), which must have a camera: colouring needs its
/// intrinsics and T_I_C. Throws ConfigError naming rig.camera otherwise.
SensorRig readColourRig(const Config& root);

/// The channels and options, for the log at start-up.
void printOptions(const ColourNodeOptions& o, std::ostream& os);

}  // namespace livo::colour
