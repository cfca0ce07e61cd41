#include "pipeline_outputs.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>

#include "livo/keyframe_t.hpp"
#include "livo/messages.hpp"
#include "livo/odometry_t.hpp"
#include "livo/time.hpp"

namespace livo {

namespace {
template <class T>
bool decodeInto(const lcm::LogEvent* ev, T& msg) {
  return msg.decode(ev->data, 0, ev->datalen) == ev->datalen;
}
}  // namespace

PipelineOutputs readPipelineOutputs(const std::string& log_path, const PipelineChannels& ch) {
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw std::runtime_error(log_path + ": cannot open as an LCM log");
  PipelineOutputs out;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    if (ev->channel == ch.odometry) {
      odometry_t m;
      if (!decodeInto(ev, m)) {
        ++out.undecodable;
        continue;
      }
      if (!allFinite(m.position, 3) || !allFinite(m.orientation, 4)) {
        ++out.non_finite;
        continue;
      }
      out.odometry.push_back({toSeconds(m.utime), poseFrom(m.position, m.orientation)});
    } else if (ev->channel == ch.keyframe) {
      keyframe_t m;
      if (!decodeInto(ev, m)) {
        ++out.undecodable;
        continue;
      }
      out.keyframes.push_back({m.id, toSeconds(m.utime), poseFrom(m.position, m.orientation)});
    } else if (ev->channel == ch.loop_correction) {
      loop_correction_t m;
      if (!decodeInto(ev, m)) {
        ++out.undecodable;
        continue;
      }
      out.last_loop = m;
      out.last_loop_after = out.odometry.empty() ? 0.0 : out.odometry.back().stamp;
      ++out.loop_corrections;
    } else if (ev->channel == ch.health) {
      health_t m;
      if (!decodeInto(ev, m)) {
        ++out.undecodable;
        continue;
      }
      out.final_health[m.node] = m;
    }
  }
  std::stable_sort(out.odometry.begin(), out.odometry.end(),
                   [](const StampedPose& a, const StampedPose& b) { return a.stamp < b.stamp; });
  std::stable_sort(out.keyframes.begin(), out.keyframes.end(),
                   [](const KeyframePose& a, const KeyframePose& b) { return a.id < b.id; });
  return out;
}

Trajectory loopCorrectedTrajectory(const PipelineOutputs& outputs) {
  if (!outputs.last_loop || outputs.keyframes.empty()) return outputs.odometry;
  const loop_correction_t& lc = *outputs.last_loop;
  std::map<int64_t, Pose3> corrected;
  for (int i = 0; i < lc.num_keyframes; ++i)
    corrected[lc.keyframe_id[i]] = poseFrom(lc.position[i].data(), lc.orientation[i].data());
  const Pose3 overall = poseFrom(lc.correction_position, lc.correction_orientation);

  // Per keyframe (by stamp): the correction that maps its published pose to its optimised one.
  struct Anchor {
    double stamp;
    Pose3 correction;
  };
  std::vector<Anchor> anchors;
  for (const KeyframePose& k : outputs.keyframes) {
    auto it = corrected.find(k.id);
    const bool adopted = it == corrected.end() && k.stamp > outputs.last_loop_after;
    const Pose3 c = it != corrected.end() ? Pose3(it->second * k.pose.inverse())
                                          : adopted ? Pose3::Identity() : overall;
    anchors.push_back({k.stamp, c});
  }
  std::stable_sort(anchors.begin(), anchors.end(), [](const Anchor& a, const Anchor& b) { return a.stamp < b.stamp; });

  Trajectory out;
  out.reserve(outputs.odometry.size());
  size_t a = 0;
  for (const StampedPose& p : outputs.odometry) {
    while (a + 1 < anchors.size() && anchors[a + 1].stamp <= p.stamp) ++a;
    // before the first keyframe the first keyframe's correction applies (it is the map origin);
    // odometry published after the LIO adopted the correction is already corrected
    const Pose3 c = p.stamp > outputs.last_loop_after ? Pose3::Identity() : anchors[a].correction;
    out.push_back({p.stamp, c * p.pose});
  }
  return out;
}

}  // namespace livo
