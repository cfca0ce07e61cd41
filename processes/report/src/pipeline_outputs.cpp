#include "livo/report/pipeline_outputs.hpp"

#include <algorithm>
#include <cstdlib>
#include <map>
#include <optional>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "livo/correction_frames.hpp"
#include "livo/filter_state_t.hpp"
#include "livo/keyframe_t.hpp"
#include "livo/map_inputs.hpp"
#include "livo/messages.hpp"
#include "livo/odometry_t.hpp"
#include "livo/time.hpp"

namespace livo::report {

namespace {
OdometryQuality qualityOf(const odometry_t& m) {
  OdometryQuality q;
  q.degenerate = m.degenerate != 0;
  q.num_residuals = m.num_residuals;
  if (allFinite(m.velocity, 3)) q.velocity = vec3From(m.velocity);
  const Mat6 P = matrixFrom<6>(m.pose_covariance);
  if (P.allFinite()) q.position_covariance = P.bottomRightCorner<3, 3>();
  return q;
}

LoopEvent loopEventOf(const loop_correction_t& m) {
  LoopEvent e;
  e.correction_id = m.correction_id;
  e.epoch = m.epoch;
  e.stamp = toSeconds(m.utime);
  e.from_id = m.loop_from_id;
  e.to_id = m.loop_to_id;
  e.fitness = m.loop_fitness;
  // T_Ck_Cj moved the newest keyframe (the largest id) from where it was onto its corrected pose
  const Pose3 step = poseFrom(m.correction_position, m.correction_orientation);
  size_t newest = 0;
  for (size_t i = 1; i < m.keyframe_id.size(); ++i)
    if (m.keyframe_id[i] > m.keyframe_id[newest]) newest = i;
  if (!m.position.empty()) {
    const Vec3 corrected(m.position[newest][0], m.position[newest][1], m.position[newest][2]);
    e.shift_m = (corrected - step.inverse() * corrected).norm();
  }
  e.turn_deg = Eigen::AngleAxisd(step.linear()).angle() * 180.0 / M_PI;
  return e;
}

template <class T>
std::vector<T> permuted(const std::vector<T>& v, const std::vector<size_t>& order) {
  std::vector<T> out;
  out.reserve(order.size());
  for (size_t i : order) out.push_back(v[i]);
  return out;
}
// The message `ev` holds, or none (counted in `undecodable`) when it does not decode.
template <class T>
std::optional<T> decoded(const lcm::LogEvent* ev, int64_t* undecodable) {
  T msg;
  if (msg.decode(ev->data, 0, ev->datalen) == ev->datalen) return msg;
  ++*undecodable;
  return std::nullopt;
}

void addOdometry(const odometry_t& m, PipelineOutputs* out) {
  if (!allFinite(m.position, 3) || !allFinite(m.orientation, 4)) {
    ++out->non_finite;
    return;
  }
  out->odometry.push_back({toSeconds(m.utime), poseFrom(m.position, m.orientation)});
  out->odometry_frames.push_back({m.epoch, m.correction_id});
  out->odometry_quality.push_back(qualityOf(m));
}

void addLoopCorrection(const loop_correction_t& m, PipelineOutputs* out) {
  Pose3 T_Ck_O;
  if (!correctionTransform(m, &T_Ck_O).empty()) {
    ++out->undecodable;
    return;
  }
  out->corrections[m.correction_id] = {m.epoch, T_Ck_O};
  auto last = out->last_loop.find(m.epoch);
  if (last == out->last_loop.end() || last->second.correction_id < m.correction_id) out->last_loop[m.epoch] = m;
  ++out->loop_corrections;
  out->loops.push_back(loopEventOf(m));
}

// lio's HEALTH "odometry reset to epoch N: why": N and why into `reasons`.
void addResetReason(const std::string& message, std::map<int32_t, std::string>* reasons) {
  const std::string tag = "odometry reset to epoch ";
  if (message.rfind(tag, 0) != 0) return;
  const size_t colon = message.find(": ", tag.size());
  if (colon != std::string::npos) (*reasons)[std::atoi(message.c_str() + tag.size())] = message.substr(colon + 2);
}

// The odometry in stamp order with its frames and qualities.
void sortOdometryByStamp(PipelineOutputs* out) {
  std::vector<size_t> order(out->odometry.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return out->odometry[a].stamp < out->odometry[b].stamp; });
  out->odometry = permuted(out->odometry, order);
  out->odometry_frames = permuted(out->odometry_frames, order);
  out->odometry_quality = permuted(out->odometry_quality, order);
}

// The first odometry of each new epoch, in stamp order (in log order, a new epoch's stamps may be
// earlier), with why lio was reset when its HEALTH said.
std::vector<OdometryReset> odometryResets(const Trajectory& odometry, const std::vector<PublishedFrame>& frames,
                                          const std::map<int32_t, std::string>& reasons) {
  std::vector<OdometryReset> resets;
  int32_t epoch = 0;
  for (size_t i = 0; i < odometry.size(); ++i) {
    if (frames[i].epoch <= epoch) continue;
    epoch = frames[i].epoch;
    auto r = reasons.find(epoch);
    resets.push_back({odometry[i].stamp, epoch, r == reasons.end() ? std::string() : r->second});
  }
  return resets;
}
}  // namespace

PipelineOutputs readPipelineOutputs(const std::string& log_path, const PipelineChannels& ch) {
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw std::runtime_error(log_path + ": cannot open as an LCM log");
  PipelineOutputs out;
  std::map<int32_t, std::string> reasons;  // epoch -> why lio was reset
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    if (ev->channel == ch.odometry) {
      if (auto m = decoded<odometry_t>(ev, &out.undecodable)) addOdometry(*m, &out);
    } else if (ev->channel == ch.keyframe) {
      if (auto m = decoded<keyframe_t>(ev, &out.undecodable))
        out.keyframes.push_back(
            {m->id, toSeconds(m->utime), poseFrom(m->position, m->orientation), {m->epoch, m->correction_id}});
    } else if (ev->channel == ch.loop_correction) {
      if (auto m = decoded<loop_correction_t>(ev, &out.undecodable)) addLoopCorrection(*m, &out);
    } else if (ev->channel == ch.state_prior) {
      ++out.state_priors;
    } else if (ev->channel == ch.state_posterior) {
      if (auto m = decoded<filter_state_t>(ev, &out.undecodable))
        out.visual_answers.push_back({toSeconds(m->utime), m->source, m->valid != 0});
    } else if (ev->channel == ch.health) {
      if (auto m = decoded<health_t>(ev, &out.undecodable)) {
        out.final_health[m->node] = *m;
        addResetReason(m->message, &reasons);
      }
    }
  }
  sortOdometryByStamp(&out);
  std::stable_sort(out.visual_answers.begin(), out.visual_answers.end(),
                   [](const VisualAnswer& a, const VisualAnswer& b) { return a.stamp < b.stamp; });
  out.resets = odometryResets(out.odometry, out.odometry_frames, reasons);
  std::stable_sort(out.keyframes.begin(), out.keyframes.end(),
                   [](const KeyframePose& a, const KeyframePose& b) { return a.id < b.id; });
  return out;
}

Trajectory loopCorrectedTrajectory(const PipelineOutputs& outputs, std::vector<std::string>* warnings) {
  if (outputs.last_loop.empty()) return outputs.odometry;
  auto rawPose = [&](const Pose3& published, const PublishedFrame& f) {
    if (f.correction_id == 0) return published;
    auto it = outputs.corrections.find(f.correction_id);
    if (it == outputs.corrections.end() || it->second.first != f.epoch)
      throw std::runtime_error("a pose of epoch " + std::to_string(f.epoch) + " includes loop correction " +
                               std::to_string(f.correction_id) + ", which is not in the log");
    return Pose3(it->second.second.inverse() * published);
  };

  // Per epoch, per keyframe (by stamp): the correction that maps its raw pose to its optimised one.
  struct Anchor {
    double stamp;
    Pose3 correction;
  };
  std::map<int32_t, std::vector<Anchor>> anchors;
  for (const auto& [epoch, lc] : outputs.last_loop) {
    std::map<int64_t, Pose3> corrected;
    if (const std::string why = correctedKeyframePoses(lc, &corrected); !why.empty())
      throw std::runtime_error("loop correction " + std::to_string(lc.correction_id) + ": " + why);
    const Pose3 overall = outputs.corrections.at(lc.correction_id).second;
    const bool has_keyframes = std::any_of(outputs.keyframes.begin(), outputs.keyframes.end(),
                                           [&](const KeyframePose& k) { return k.frame.epoch == epoch; });
    if (!has_keyframes) {
      // nothing ties a pose to a keyframe's correction: the poses stay as published (online)
      if (warnings)
        warnings->push_back("loop corrections of odometry epoch " + std::to_string(epoch) +
                            " but no KEYFRAME recorded for it: trajectory.tum holds the online odometry there, "
                            "not the loop-corrected trajectory (record KEYFRAME)");
      continue;
    }
    std::vector<Anchor>& a = anchors[epoch];
    for (const KeyframePose& k : outputs.keyframes) {
      if (k.frame.epoch != epoch) continue;
      auto it = corrected.find(k.id);
      a.push_back({k.stamp, it != corrected.end() ? Pose3(it->second * rawPose(k.pose, k.frame).inverse()) : overall});
    }
    std::stable_sort(a.begin(), a.end(), [](const Anchor& x, const Anchor& y) { return x.stamp < y.stamp; });
  }

  Trajectory out;
  out.reserve(outputs.odometry.size());
  std::map<int32_t, size_t> next;  // per epoch: the anchor in use
  for (size_t i = 0; i < outputs.odometry.size(); ++i) {
    const StampedPose& p = outputs.odometry[i];
    const PublishedFrame& f = outputs.odometry_frames[i];
    auto a = anchors.find(f.epoch);
    if (a == anchors.end()) {  // no loop in this epoch: the odometry is final (it adopted none)
      out.push_back(p);
      continue;
    }
    // before the first keyframe the first keyframe's correction applies (it is the map origin)
    size_t& k = next[f.epoch];
    while (k + 1 < a->second.size() && a->second[k + 1].stamp <= p.stamp) ++k;
    out.push_back({p.stamp, a->second[k].correction * rawPose(p.pose, f)});
  }
  return out;
}

std::string resetsJson(const std::vector<OdometryReset>& resets) {
  nlohmann::json j = nlohmann::json::array();
  for (const OdometryReset& r : resets) j.push_back({{"time", r.stamp}, {"epoch", r.epoch}, {"reason", r.reason}});
  return j.dump(2) + "\n";
}

}  // namespace livo::report
