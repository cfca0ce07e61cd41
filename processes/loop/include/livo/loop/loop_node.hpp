// The livo-loop node: KEYFRAME in, LOOP_CORRECTION out (all keyframe ids with corrected poses
// after each accepted loop), output files at shutdown. Work depends only on message contents.
#pragma once

#include <string>

#include <lcm/lcm-cpp.hpp>

#include "livo/config.hpp"
#include "livo/keyframe_t.hpp"
#include "livo/loop/loop_closer.hpp"
#include "livo/loop/loop_config.hpp"
#include "livo/node.hpp"

namespace livo::loop {

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
