#include "livo/map_inputs.hpp"

#include <algorithm>

#include "livo/keyframe_t.hpp"
#include "livo/loop_correction_t.hpp"
#include "livo/message_checks.hpp"
#include "livo/messages.hpp"
#include "livo/node.hpp"
#include "livo/registered_scan_t.hpp"

namespace livo {

std::string viewRegisteredScan(const registered_scan_t& m, RegisteredScanView* v) {
  if (std::string why = registeredScanProblem(m); !why.empty()) return why;
  const point_cloud_t& c = m.cloud;
  v->utime = m.utime;
  v->cloud_utime = c.utime;
  v->T_W_I = poseFrom(m.position, m.orientation);
  v->num_points = c.num_points;
  v->x = c.x.data();
  v->y = c.y.data();
  v->z = c.z.data();
  v->time_offset = c.time_offset.data();
  return "";
}

void moveRegisteredScan(const Pose3& T, registered_scan_t* m) {
  poseTo(T * poseFrom(m->position, m->orientation), m->position, m->orientation);
  point_cloud_t& c = m->cloud;
  const size_t n = std::min({c.x.size(), c.y.size(), c.z.size()});
  for (size_t i = 0; i < n; ++i) {
    const Vec3 p = T * Vec3(c.x[i], c.y[i], c.z[i]);
    c.x[i] = static_cast<float>(p.x());
    c.y[i] = static_cast<float>(p.y());
    c.z[i] = static_cast<float>(p.z());
  }
}

std::string keyframeProblem(const keyframe_t& m) {
  if (std::string why = poseProblem(m.position, m.orientation); !why.empty()) return why;
  const point_cloud_t& c = m.cloud;
  const size_t n = static_cast<size_t>(std::max(0, c.num_points));
  if (c.x.size() != n || c.y.size() != n || c.z.size() != n) return "cloud arrays disagree with num_points";
  if (c.frame != "I") return "cloud frame is '" + c.frame + "', expected I";
  return "";
}

std::string correctedKeyframePoses(const loop_correction_t& m, std::map<int64_t, Pose3>* poses) {
  const size_t n = static_cast<size_t>(std::max(0, m.num_keyframes));
  if (m.keyframe_id.size() != n || m.position.size() != n || m.orientation.size() != n)
    return "arrays disagree with num_keyframes";
  std::map<int64_t, Pose3> out;
  for (size_t i = 0; i < n; ++i) {
    if (m.position[i].size() != 3 || m.orientation[i].size() != 4) return "malformed corrected pose";
    if (std::string why = poseProblem(m.position[i].data(), m.orientation[i].data()); !why.empty())
      return "corrected " + why;
    out[m.keyframe_id[i]] = poseFrom(m.position[i].data(), m.orientation[i].data());
  }
  *poses = std::move(out);
  return "";
}

std::string viewRegisteredScanInMap(const registered_scan_t& m, const MapFrame::Placed& placed,
                                    registered_scan_t* moved, RegisteredScanView* view) {
  if (placed.placement != MapFrame::Placement::kUse) return placed.why;
  if (!placed.moved) return viewRegisteredScan(m, view);
  // published before the LIO adopted the map's loop correction (or after one not here yet)
  *moved = m;
  moveRegisteredScan(placed.to_map, moved);
  return viewRegisteredScan(*moved, view);
}

MapCorrection readMapCorrection(const loop_correction_t& m, MapFrame* frame) {
  MapCorrection c;
  Pose3 T_Ck_O;
  c.problem = correctedKeyframePoses(m, &c.corrected);
  if (c.problem.empty()) c.problem = correctionTransform(m, &T_Ck_O);
  if (c.problem.empty()) c.step = frame->addCorrection(m.correction_id, m.epoch, T_Ck_O);
  return c;
}

bool takeRegisteredScan(Node& node, const std::string& channel, const registered_scan_t& m,
                        const MapFrame::Placed& placed,
                        const std::function<bool(const RegisteredScanView&, std::string* why)>& add) {
  registered_scan_t moved;
  RegisteredScanView view;
  std::string why = viewRegisteredScanInMap(m, placed, &moved, &view);
  if (why.empty() && add(view, &why)) return true;
  node.reject(channel, why);
  return false;
}

bool takeKeyframePose(Node& node, const std::string& channel, const keyframe_t& m, bool cloud,
                      const std::function<MapFrame::Placed()>& place, Pose3* T_map_I) {
  if (const std::string why = cloud ? keyframeProblem(m) : poseProblem(m.position, m.orientation); !why.empty()) {
    node.reject(channel, why);
    return false;
  }
  const MapFrame::Placed placed = place();
  if (placed.placement != MapFrame::Placement::kUse) {
    node.reject(channel, placed.why);
    return false;
  }
  *T_map_I = placed.to_map * poseFrom(m.position, m.orientation);
  return true;
}

bool takeMapCorrection(Node& node, const std::string& channel, const loop_correction_t& m, MapFrame* frame,
                       MapCorrection* correction) {
  *correction = readMapCorrection(m, frame);
  if (!correction->problem.empty()) {
    node.reject(channel, correction->problem);
    return false;
  }
  if (!correction->step.apply) {
    node.info("loop correction " + std::to_string(m.correction_id) + " not applied: " + correction->step.why);
    return false;
  }
  return true;
}

}  // namespace livo
