#include "livo/correction_frames.hpp"

#include <stdexcept>

#include "livo/loop_correction_t.hpp"
#include "livo/message_checks.hpp"
#include "livo/messages.hpp"

namespace livo {

std::string correctionTransform(const loop_correction_t& m, Pose3* T_Ck_O) {
  if (m.correction_id < 1) return "correction_id " + std::to_string(m.correction_id) + " (must be >= 1)";
  if (std::string why = poseProblem(m.odometry_to_corrected_position, m.odometry_to_corrected_orientation);
      !why.empty())
    return "odometry_to_corrected: " + why;
  *T_Ck_O = poseFrom(m.odometry_to_corrected_position, m.odometry_to_corrected_orientation);
  return "";
}

void CorrectionTable::add(int64_t id, int32_t epoch, const Pose3& T_Ck_O) {
  if (id < 1) throw std::invalid_argument("loop correction id " + std::to_string(id) + " (must be >= 1)");
  corrections_[id] = Entry{epoch, T_Ck_O};
}

std::optional<Pose3> CorrectionTable::odometryToCorrected(int32_t epoch, int64_t id) const {
  if (id == 0) return Pose3::Identity();
  auto it = corrections_.find(id);
  if (it == corrections_.end() || it->second.epoch != epoch) return std::nullopt;
  return it->second.T_Ck_O;
}

std::optional<Pose3> CorrectionTable::between(int32_t epoch, int64_t from, int64_t to) const {
  if (from == to) return Pose3::Identity();
  const auto T_from = odometryToCorrected(epoch, from), T_to = odometryToCorrected(epoch, to);
  if (!T_from || !T_to) return std::nullopt;
  return Pose3(*T_to * T_from->inverse());
}

int64_t CorrectionTable::newest(int32_t epoch) const {
  for (auto it = corrections_.rbegin(); it != corrections_.rend(); ++it)
    if (it->second.epoch == epoch) return it->first;
  return 0;
}

void CorrectionTable::forgetEpochsBefore(int32_t epoch) {
  for (auto it = corrections_.begin(); it != corrections_.end();)
    it = it->second.epoch < epoch ? corrections_.erase(it) : std::next(it);
}

MapFrame::Placed MapFrame::place(int32_t epoch, int64_t correction_id,
                                 const std::function<void(int32_t)>& close_epoch) {
  Placed p;
  if (!started_) startEpoch(epoch, correction_id);
  if (epoch > epoch_) {
    close_epoch(epoch_);
    startEpoch(epoch, correction_id);
  }
  if (epoch < epoch_) {
    p.placement = Placement::kOldEpoch;
    p.why = "made in odometry epoch " + std::to_string(epoch) + ", the map is in epoch " + std::to_string(epoch_) +
            " (after a LIO reset): dropped";
    return p;
  }
  const auto T = table_.between(epoch, correction_id, correction_id_);
  if (!T) {
    p.placement = Placement::kUnknownFrame;
    p.why = "made in loop correction " + std::to_string(correction_id) + " of epoch " + std::to_string(epoch) +
            ", which never arrived here: dropped";
    return p;
  }
  p.to_map = *T;
  p.moved = correction_id != correction_id_;
  return p;
}

void MapFrame::startEpoch(int32_t epoch, int64_t correction_id) {
  started_ = true;
  epoch_ = epoch;
  correction_id_ = correction_id;
  table_.forgetEpochsBefore(epoch);
}

MapFrame::CorrectionStep MapFrame::addCorrection(int64_t correction_id, int32_t epoch, const Pose3& T_Ck_O) {
  table_.add(correction_id, epoch, T_Ck_O);
  CorrectionStep s;
  if (!started_) {
    s.why = "no map yet";
    return s;
  }
  if (epoch != epoch_) {
    s.why = "for odometry epoch " + std::to_string(epoch) + ", the map is in epoch " + std::to_string(epoch_);
    return s;
  }
  if (correction_id <= correction_id_) {
    s.why = "the map is already in correction " + std::to_string(correction_id_) + " (late or repeated)";
    return s;
  }
  const auto T = table_.between(epoch, correction_id_, correction_id);
  if (!T) {  // the map frame's own correction is always known; kept for safety
    s.why = "the map frame's correction is unknown";
    return s;
  }
  s.apply = true;
  s.unlisted = *T;
  correction_id_ = correction_id;
  return s;
}

}  // namespace livo
