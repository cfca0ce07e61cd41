// Reads the `octomap:` section of a project config (strict: unknown keys are errors).
#pragma once

#include <iosfwd>
#include <string>

#include "livo/config.hpp"
#include "livo/octomap/octomap_options.hpp"

namespace livo::octomap {

struct OctomapNodeOptions {
  OctomapOptions core;
  std::string registered_scan_channel = "REGISTERED_SCAN";
  std::string colored_cloud_channel = "COLORED_CLOUD";
  std::string keyframe_channel = "KEYFRAME";
  std::string loop_correction_channel = "LOOP_CORRECTION";
  std::string octomap_channel = "OCTOMAP";
  double publish_period_s = 2.0;     // sensor time between OCTOMAP messages (0: never)
  double write_period_s = 10.0;      // sensor time between file writes (0: only on exit)
  std::string map_name = "octomap";  // files <output_dir>/<map_name>.bt / .ot
};

OctomapNodeOptions readOctomapNodeOptions(const Config& root);

/// The channels and options, for the log at start-up.
void printOptions(const OctomapNodeOptions& o, std::ostream& os);

}  // namespace livo::octomap
