// What a pipeline run left in its recorded outputs log: the online odometry, the keyframes, the
// last loop correction, and every node's final HEALTH.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "livo/health_t.hpp"
#include "livo/loop_correction_t.hpp"
#include "livo/trajectory_io.hpp"

namespace livo {

struct PipelineChannels {
  std::string odometry = "ODOMETRY";
  std::string keyframe = "KEYFRAME";
  std::string loop_correction = "LOOP_CORRECTION";
  std::string health = "HEALTH";
};

struct KeyframePose {
  int64_t id = 0;
  double stamp = 0.0;
  Pose3 pose = Pose3::Identity();  // as published (odometry frame at that time)
};

struct PipelineOutputs {
  Trajectory odometry;                          // body pose at every scan, in stamp order
  std::vector<KeyframePose> keyframes;          // in id order
  std::optional<loop_correction_t> last_loop;   // the newest LOOP_CORRECTION
  double last_loop_after = 0.0;  // stamp of the newest odometry logged before it: later odometry and
                                 // keyframes come from a LIO that had adopted it (design.md)
  int64_t loop_corrections = 0;
  std::map<std::string, health_t> final_health; // newest HEALTH per node
  int64_t undecodable = 0;                      // messages on these channels that did not decode
  int64_t non_finite = 0;                       // odometry poses dropped for NaN/Inf
};

/// Reads the log; throws std::runtime_error naming the file if it cannot be opened.
PipelineOutputs readPipelineOutputs(const std::string& log_path, const PipelineChannels& channels = {});

/// The final trajectory: each odometry pose moved by the correction of the newest keyframe at or
/// before it, T = K_corrected * K_published^-1 * T_odometry, using the last loop correction's
/// keyframe poses; keyframes newer than it keep its overall correction, unless they were published
/// after it, by a LIO that had adopted it: those, and the odometry after them, are final as they
/// are. Identical to the odometry when there was no loop correction.
Trajectory loopCorrectedTrajectory(const PipelineOutputs& outputs);

}  // namespace livo
