// LOOP_CORRECTION as an odometry process (livo-lio, livo-lio-graph) takes it: the message read
// into a LoopCorrection and the corrected keyframe poses, and whether the process adopts it.
#pragma once

#include <string>
#include <vector>

#include "livo/loop_correction_t.hpp"
#include "livo/odometry_frame.hpp"

namespace livo {

/// The loop correction (id, transforms) and the corrected keyframe poses (in id order). False
/// with the reason for a malformed message (bad poses or arrays, previous_correction_id not
/// before correction_id).
bool fromMessage(const loop_correction_t& m, LoopCorrection* correction, std::vector<KeyframePose>* poses,
                 std::string* why);

/// Why an estimator in `frame` does not adopt the correction: made for another odometry epoch, or
/// not newer than the correction it already adopted (late or repeated); "" if it adopts it.
std::string adoptionRefusal(const loop_correction_t& m, const OdometryFrame& frame);

}  // namespace livo
