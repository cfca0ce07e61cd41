// The livo-loop node: KEYFRAME in, LOOP_CORRECTION out (all keyframe ids with corrected poses
// after each accepted loop), output files at shutdown. Work depends only on message contents.
#pragma once

#include <string>

#include <lcm/lcm-cpp.hpp>

#include "livo/config.hpp"
#include "livo/keyframe_t.hpp"
#include "livo/node.hpp"
#include "loop_closer.hpp"

namespace livo::loop {

struct LoopNodeOptions {
  std::string keyframe_channel = "KEYFRAME";
  std::string loop_correction_channel = "LOOP_CORRECTION";
  std::string output_dir;            // empty: no files
  double global_map_voxel = 0.2;     // m
  LoopCloserOptions closer;
};

/// Reads the optional `loop:` section of a project config (absent keys keep the defaults) and
/// the channel names from `rig.channels` / `loop.channels` if present.
LoopNodeOptions readLoopNodeOptions(const Config& root);

class LoopNode {
 public:
  LoopNode(lcm::LCM& lcm, NodeOptions node_options, LoopNodeOptions options);
  Node& node() { return node_; }
  const LoopCloser& closer() const { return closer_; }
  /// Writes the output files (if an output folder is set).
  void writeOutputs();
  /// Loops accepted, corrections published and loops refused by the consistency check, by reason.
  std::string summary() const;

 private:
  void onKeyframe(const keyframe_t& msg);
  void publishCorrection(const AcceptedLoop& loop, const Correction& correction, int64_t utime);

  Node node_;
  LoopNodeOptions options_;
  LoopCloser closer_;
};

}  // namespace livo::loop
