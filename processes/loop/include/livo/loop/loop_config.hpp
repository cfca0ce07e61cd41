// Options of the livo-loop node, read from the optional `loop:` section of a project config
// (every key optional, unknown keys are errors).
#pragma once

#include <iosfwd>
#include <string>

#include "livo/config.hpp"
#include "livo/loop/loop_closer.hpp"

namespace livo::loop {

struct LoopNodeOptions {
  std::string keyframe_channel = "KEYFRAME";
  std::string loop_correction_channel = "LOOP_CORRECTION";
  std::string output_dir;         // empty: no files
  double global_map_voxel = 0.2;  // m
  LoopCloserOptions core;
};

/// Reads the optional `loop:` section of a project config (absent keys keep the defaults) and
/// the channel names from `loop.channels` (strict: unknown keys are errors).
LoopNodeOptions readLoopNodeOptions(const Config& root);

/// The channels and options, for the log at start-up.
void printOptions(const LoopNodeOptions& o, std::ostream& os);

}  // namespace livo::loop
