// Loop corrections for the tests of the map builders and their inputs (livo-colour, livo-octomap,
// livo/map_inputs.hpp): a correction's keyframe list filled from (keyframe id, pose) pairs.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "livo/loop_correction_t.hpp"
#include "livo/messages.hpp"

namespace livo_test {

/// `poses` as the keyframes `m` lists: num_keyframes, keyframe_id, position and orientation.
inline void setKeyframePoses(const std::vector<std::pair<int64_t, livo::Pose3>>& poses, livo::loop_correction_t* m) {
  m->num_keyframes = static_cast<int32_t>(poses.size());
  for (const auto& [id, T] : poses) {
    m->keyframe_id.push_back(id);
    std::vector<double> p(3), q(4);
    livo::poseTo(T, p.data(), q.data());
    m->position.push_back(p);
    m->orientation.push_back(q);
  }
}

}  // namespace livo_test
