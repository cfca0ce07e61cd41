// What the map builders (livo-colour, livo-octomap) take from the LIO and the loop closure, checked
// the same way for every consumer: a registered scan as plain arrays with its pose, a keyframe, and
// a loop correction's corrected keyframe poses. RegisteredScanView is LCM-free, so the map cores
// take it without knowing the messages; the functions (in livo_node) read the messages.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "livo/correction_frames.hpp"
#include "livo/so3.hpp"

namespace livo {

class registered_scan_t;
class keyframe_t;
class loop_correction_t;

/// A registered scan (world frame) as views into the message's arrays: valid while it lives.
struct RegisteredScanView {
  int64_t utime = 0;        // sweep end: the pose's time
  int64_t cloud_utime = 0;  // point j was measured at cloud_utime + time_offset[j]
  Pose3 T_W_I = Pose3::Identity();
  int num_points = 0;
  const float* x = nullptr;
  const float* y = nullptr;
  const float* z = nullptr;
  const float* time_offset = nullptr;  // may be null: every point at cloud_utime
};

/// The view of `m`, or why it cannot be used (registeredScanProblem()); "" when `view` was filled.
std::string viewRegisteredScan(const registered_scan_t& m, RegisteredScanView* view);

/// Moves a registered scan (its pose and world-frame points) by T: a scan published in another
/// loop correction's frame brought into a map's (MapFrame).
void moveRegisteredScan(const Pose3& T, registered_scan_t* m);

/// Why a KEYFRAME cannot be used for map rebuilds: a bad pose, cloud arrays that disagree with
/// num_points, a cloud not in the body frame "I"; "" if it can.
std::string keyframeProblem(const keyframe_t& m);

/// The corrected keyframe poses of a LOOP_CORRECTION (id -> W_T_I), or why it cannot be used
/// (arrays that disagree with num_keyframes, a bad pose); "" when `poses` was filled.
std::string correctedKeyframePoses(const loop_correction_t& m, std::map<int64_t, Pose3>* poses);

/// The view of a registered scan in a map's frame, `placed` being MapFrame::place() of its epoch
/// and correction: a scan made in another correction's frame is first moved into `*moved` (the view
/// then points into it). "" when `view` was filled, else why the scan is not used (placement,
/// viewRegisteredScan()).
std::string viewRegisteredScanInMap(const registered_scan_t& m, const MapFrame::Placed& placed,
                                    registered_scan_t* moved, RegisteredScanView* view);

/// A LOOP_CORRECTION as a map builder takes it: `problem` says why the message is refused
/// (correctedKeyframePoses(), correctionTransform()); otherwise it was recorded in the MapFrame and
/// `step` says whether the map moves to it, `corrected` holding the corrected keyframe poses.
struct MapCorrection {
  std::string problem;
  std::map<int64_t, Pose3> corrected;  // keyframe id -> W_T_I in the corrected frame
  MapFrame::CorrectionStep step;
};
MapCorrection readMapCorrection(const loop_correction_t& m, MapFrame* frame);

class Node;

// The three inputs as a map-building node takes them, a refusal said on its node (Node::reject on
// `channel`) and the message then dropped, so that every map builder refuses alike.

/// A REGISTERED_SCAN's view in the map's frame (viewRegisteredScanInMap()) given to `add`, which
/// says why it refuses it (as the map cores' addScan); false if refused.
bool takeRegisteredScan(Node& node, const std::string& channel, const registered_scan_t& m,
                        const MapFrame::Placed& placed,
                        const std::function<bool(const RegisteredScanView&, std::string* why)>& add);

/// A KEYFRAME's pose in the map's frame (the placement's to_map times its pose); false if refused:
/// a bad pose (poseProblem(), or with `cloud` keyframeProblem(): the cloud too), or a placement
/// other than kUse. `place` (MapFrame::place() of the keyframe's epoch and correction, which may
/// start a new epoch) is called only for a sound message.
bool takeKeyframePose(Node& node, const std::string& channel, const keyframe_t& m, bool cloud,
                      const std::function<MapFrame::Placed()>& place, Pose3* T_map_I);

/// A LOOP_CORRECTION the map moves to (readMapCorrection()); false if refused or not applied (the
/// latter said as a Node::info line with the step's reason).
bool takeMapCorrection(Node& node, const std::string& channel, const loop_correction_t& m, MapFrame* frame,
                       MapCorrection* correction);

}  // namespace livo
