// Files livo-loop writes at shutdown into its output folder: the optimised keyframe trajectory
// (keyframes.tum), the accepted loops (loops.json) and a global map (global_map.ply, binary).
#pragma once

#include <string>

#include "livo/loop/loop_closer.hpp"

namespace livo::loop {

void writeKeyframeTrajectory(const std::string& path, const LoopCloser& closer);
void writeLoopsJson(const std::string& path, const LoopCloser& closer);
/// Keyframe clouds in their optimised poses, voxel-downsampled to `voxel_size`.
void writeGlobalMapPly(const std::string& path, const LoopCloser& closer, double voxel_size);
/// All three into `dir` (created if missing).
void writeLoopOutputs(const std::string& dir, const LoopCloser& closer, double map_voxel_size);

}  // namespace livo::loop
