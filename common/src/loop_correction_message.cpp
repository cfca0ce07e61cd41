#include "livo/loop_correction_message.hpp"

#include <map>

#include "livo/correction_frames.hpp"
#include "livo/map_inputs.hpp"
#include "livo/message_checks.hpp"
#include "livo/messages.hpp"

namespace livo {

bool fromMessage(const loop_correction_t& m, LoopCorrection* correction, std::vector<KeyframePose>* poses,
                 std::string* why) {
  std::map<int64_t, Pose3> corrected;
  if (std::string problem = correctedKeyframePoses(m, &corrected); !problem.empty()) {
    *why = "loop correction: " + problem;
    return false;
  }
  if (std::string problem = poseProblem(m.correction_position, m.correction_orientation); !problem.empty()) {
    *why = "loop correction transform: " + problem;
    return false;
  }
  if (std::string problem = correctionTransform(m, &correction->T_Ck_O); !problem.empty()) {
    *why = "loop correction: " + problem;
    return false;
  }
  if (m.previous_correction_id < 0 || m.previous_correction_id >= m.correction_id) {
    *why = "loop correction " + std::to_string(m.correction_id) + ": previous_correction_id " +
           std::to_string(m.previous_correction_id) + " is not before it";
    return false;
  }
  correction->id = m.correction_id;
  correction->previous_id = m.previous_correction_id;
  correction->T_Ck_Cj = poseFrom(m.correction_position, m.correction_orientation);
  poses->clear();
  for (const auto& [id, pose] : corrected) poses->push_back({id, pose});
  return true;
}

std::string adoptionRefusal(const loop_correction_t& m, const OdometryFrame& frame) {
  if (m.epoch != frame.epoch)
    return "loop correction " + std::to_string(m.correction_id) + " is for odometry epoch " + std::to_string(m.epoch) +
           ", the filter is in epoch " + std::to_string(frame.epoch) + ": ignored";
  if (m.correction_id <= frame.correction_id)
    return "loop correction " + std::to_string(m.correction_id) + " is not after the adopted one (" +
           std::to_string(frame.correction_id) + "): ignored";
  return "";
}

}  // namespace livo
