// The two cross-process hand-offs of the odometry frame (lcmtypes/loop_correction_t.lcm):
// loop corrections (a LIO that adopted correction k publishes in the corrected frame C_k and says
// so in correction_id) and odometry epochs (a LIO reset restarts the odometry in a new frame).
//
// CorrectionTable keeps the corrections a process received or published (T_Ck_O per id and
// epoch), so that a pose published in any correction's frame can be brought into any other of the
// same epoch, whatever the order in which poses and corrections arrived.
//
// MapFrame is what a map builder (livo-colour, livo-octomap) does with it: its map is in one
// frame (an epoch and a correction id); every input pose is placed into that frame, a newer
// epoch starts a new map, a newer correction moves the map.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include "livo/so3.hpp"

namespace livo {

class loop_correction_t;

/// T_Ck_O of a LOOP_CORRECTION (odometry_to_corrected), or why it cannot be used (a bad pose,
/// correction_id < 1); "" when `T` was filled.
std::string correctionTransform(const loop_correction_t& m, Pose3* T_Ck_O);

class CorrectionTable {
 public:
  /// Records correction `id` of `epoch` (T_Ck_O). Throws std::invalid_argument for id < 1.
  /// A repeated id replaces the entry.
  void add(int64_t id, int32_t epoch, const Pose3& T_Ck_O);
  /// T_Ck_O of correction `id` of `epoch`: identity for id 0 (the raw frame), nullopt if unknown
  /// or of another epoch.
  std::optional<Pose3> odometryToCorrected(int32_t epoch, int64_t id) const;
  /// T_Cto_Cfrom: moves a pose published in correction `from` onto correction `to` (same epoch);
  /// nullopt if either is unknown.
  std::optional<Pose3> between(int32_t epoch, int64_t from, int64_t to) const;
  /// The newest correction of `epoch`, 0 if none.
  int64_t newest(int32_t epoch) const;
  /// Forgets the corrections of epochs before `epoch`.
  void forgetEpochsBefore(int32_t epoch);
  size_t size() const { return corrections_.size(); }

 private:
  struct Entry {
    int32_t epoch;
    Pose3 T_Ck_O;
  };
  std::map<int64_t, Entry> corrections_;  // by id
};

class MapFrame {
 public:
  enum class Placement {
    kUse,           // `to_map` moves the pose (and world-frame points) into the map frame
    kOldEpoch,      // from an epoch the map has left: drop it
    kUnknownFrame,  // in a correction this process never received (lost): drop it
  };
  struct Placed {
    Placement placement = Placement::kUse;
    Pose3 to_map = Pose3::Identity();
    bool moved = false;  // to_map is not the identity (the pose was made in another correction)
    std::string why;     // for the drops
  };

  /// Where a pose published in (epoch, correction_id) goes. The first pose ever starts the map
  /// in its own frame; a pose of a newer epoch (the LIO was reset) first calls
  /// `close_epoch(old epoch)`, which must drop (or write out) the map, then starts a new map in
  /// its own frame.
  Placed place(int32_t epoch, int64_t correction_id, const std::function<void(int32_t)>& close_epoch);

  struct CorrectionStep {
    bool apply = false;                  // the map moves: corrected keyframe poses, `unlisted` for the rest
    Pose3 unlisted = Pose3::Identity();  // T_Ck_Cmap: for map content of keyframes the correction does not list
    std::string why;                     // when !apply: why it is not applied now
  };
  /// Records a correction (always, for later placements) and says whether the map moves to it:
  /// only a correction of the map's epoch newer than the map frame does.
  CorrectionStep addCorrection(int64_t correction_id, int32_t epoch, const Pose3& T_Ck_O);

  bool started() const { return started_; }
  int32_t epoch() const { return epoch_; }
  int64_t correctionId() const { return correction_id_; }

 private:
  void startEpoch(int32_t epoch, int64_t correction_id);

  CorrectionTable table_;
  bool started_ = false;
  int32_t epoch_ = 0;
  int64_t correction_id_ = 0;  // the frame the map is in
};

}  // namespace livo
