#include "livo/loop/loop_node.hpp"

#include <cmath>
#include <sstream>

#include "livo/loop/loop_outputs.hpp"
#include "livo/loop_correction_t.hpp"
#include "livo/messages.hpp"

namespace livo::loop {

LoopNode::LoopNode(lcm::LCM& lcm, NodeOptions node_options, LoopNodeOptions options)
    : node_(lcm, std::move(node_options)), options_(std::move(options)), closer_(options_.core) {
  node_.declareOutput(options_.loop_correction_channel);
  node_.subscribe<keyframe_t>(options_.keyframe_channel, [this](const keyframe_t& m) { onKeyframe(m); });
}

void LoopNode::onKeyframe(const keyframe_t& m) {
  const std::string& ch = options_.keyframe_channel;
  if (!allFinite(m.position, 3) || !allFinite(m.orientation, 4)) {
    node_.reject(ch, "keyframe " + std::to_string(m.id) + " has a non-finite pose");
    return;
  }
  const double qn = std::sqrt(m.orientation[0] * m.orientation[0] + m.orientation[1] * m.orientation[1] +
                              m.orientation[2] * m.orientation[2] + m.orientation[3] * m.orientation[3]);
  if (qn < 1e-6) {
    node_.reject(ch, "keyframe " + std::to_string(m.id) + " has a zero quaternion");
    return;
  }
  const point_cloud_t& c = m.cloud;
  if (c.num_points < 0 || static_cast<size_t>(c.num_points) != c.x.size() || c.x.size() != c.y.size() ||
      c.x.size() != c.z.size()) {
    node_.reject(ch, "keyframe " + std::to_string(m.id) + " has inconsistent cloud arrays");
    return;
  }
  if (!c.frame.empty() && c.frame != "I")
    node_.warn("keyframe " + std::to_string(m.id) + " cloud is in frame '" + c.frame + "', expected 'I'; used as I");
  KeyframeInput in;
  in.id = m.id;
  in.utime = m.utime;
  in.epoch = m.epoch;
  in.correction_id = m.correction_id;
  if (const std::string why = closer_.problem(in); !why.empty()) {
    node_.reject(ch, why);
    return;
  }
  if (closer_.size() > 0 && m.epoch > closer_.epoch(closer_.newestId()))
    node_.warn("keyframe " + std::to_string(m.id) + " starts odometry epoch " + std::to_string(m.epoch) +
               " (the LIO was reset): a new graph segment, no odometry edge to the previous keyframe");
  in.pose = poseFrom(m.position, m.orientation);
  in.covariance = matrixFrom<6>(m.pose_covariance);
  in.relative_to_id = m.relative_to_id;
  in.relative_covariance = matrixFrom<6>(m.relative_covariance);
  in.relative_covariance_held_calibration = matrixFrom<6>(m.relative_covariance_held_calibration);
  in.cloud.reserve(c.x.size());
  size_t non_finite = 0;
  for (size_t i = 0; i < c.x.size(); ++i) {
    const Vec3 p(c.x[i], c.y[i], c.z[i]);
    if (p.allFinite())
      in.cloud.push_back(p);
    else
      ++non_finite;
  }
  if (non_finite > 0)
    node_.warn("keyframe " + std::to_string(m.id) + ": dropped " + std::to_string(non_finite) + " non-finite points");
  if (in.cloud.empty())
    node_.warn("keyframe " + std::to_string(m.id) + " has no points: kept in the graph, not used for loops");
  const int64_t unusable_held_parts = closer_.unusableHeldParts();
  const AddResult r = closer_.addKeyframe(in);
  if (unusable_held_parts == 0 && closer_.unusableHeldParts() > 0)
    node_.warn("keyframe " + std::to_string(m.id) +
               ": the held-calibration part of the increment's covariance is not finite or larger than the whole; "
               "the whole is composed for such increments (said once; counted in the summary)");
  for (const LoopRegistrationResult& a : r.attempts) {
    if (a.fine.iterations == 0) continue;  // stopped at the coarse stage
    std::ostringstream s;
    s << "keyframe " << m.id << ": candidate fitness " << a.fine.fitness << ", overlap " << a.fine.overlap
      << ", translation eigenvalue " << a.fine.min_translation_eigenvalue << " (ratio "
      << a.fine.translation_eigenvalue_ratio << "): " << (a.accepted ? "accepted" : a.reason);
    node_.info(s.str());
  }
  for (const RefusedLoop& f : r.refused)
    node_.warn((f.merged ? "keyframe " : "loop ") + std::to_string(f.from_id) + (f.merged ? " joining " : " -> ") +
               std::to_string(f.to_id) + " refused (" + std::to_string(closer_.refusedLoops().size()) +
               " so far): " + f.reason);
  if (r.loop) {
    std::ostringstream s;
    s << (r.loop->merged ? "keyframe " : "loop ") << r.loop->from_id << (r.loop->merged ? " joins " : " -> ")
      << r.loop->to_id << " accepted (inliers " << r.loop->coarse_inliers << ", fitness " << r.loop->fitness
      << ", overlap " << r.loop->overlap << "; residual " << r.loop->residual_translation << " m, "
      << r.loop->residual_rotation * 180.0 / M_PI << " deg)";
    if (!r.correction) s << ": the estimate agrees, no correction";
    node_.info(s.str());
    if (r.correction) publishCorrection(*r.loop, *r.correction, m.utime);
  }
}

void LoopNode::publishCorrection(const AcceptedLoop& loop, const Correction& correction, int64_t utime) {
  loop_correction_t msg;
  msg.utime = utime;
  msg.correction_id = correction.id;
  msg.epoch = correction.epoch;
  msg.loop_from_id = loop.from_id;
  msg.loop_to_id = loop.to_id;
  msg.loop_fitness = loop.fitness;
  poseTo(correction.T_Ck_Cj, msg.correction_position, msg.correction_orientation);
  msg.previous_correction_id = correction.previous_id;
  poseTo(correction.T_Ck_O, msg.odometry_to_corrected_position, msg.odometry_to_corrected_orientation);
  // the keyframes of the correction's epoch (the others are in unrelated frames)
  closer_.forEachPose([&](int64_t id, const Pose3& T) {
    if (closer_.epoch(id) != correction.epoch) return;
    msg.keyframe_id.push_back(id);
    std::vector<double> p(3), q(4);
    poseTo(T, p.data(), q.data());
    msg.position.push_back(p);
    msg.orientation.push_back(q);
  });
  msg.num_keyframes = static_cast<int32_t>(msg.keyframe_id.size());
  node_.publish(options_.loop_correction_channel, msg);
}

std::string LoopNode::summary() const {
  size_t by_odometry = 0;
  for (const RefusedLoop& f : closer_.refusedLoops()) by_odometry += f.against == "odometry";
  const size_t refused = closer_.refusedLoops().size();
  const ReasonCounts& rejected = closer_.rejectedRegistrations();
  std::string registered = std::to_string(closer_.registrations()) + " candidates registered";
  if (!rejected.empty()) registered += " (" + rejected.summary(std::to_string(rejected.total()) + " rejected") + ")";
  std::string out = registered + ", " + std::to_string(closer_.loops().size()) + " loops, " +
                    std::to_string(closer_.corrections()) + " corrections, " + std::to_string(refused) +
                    " refused as inconsistent (" + std::to_string(by_odometry) + " with the odometry, " +
                    std::to_string(refused - by_odometry) + " with an earlier loop)";
  if (closer_.unusableHeldParts() > 0)
    out += ", " + std::to_string(closer_.unusableHeldParts()) +
           " increments composed with their held-calibration part (it was unusable)";
  return out;
}

void LoopNode::writeOutputs() {
  if (options_.output_dir.empty()) {
    node_.info(summary());
    return;
  }
  if (options_.core.optimize_at_exit && closer_.optimizePendingLoops())
    node_.info("optimised the graph once more with the loops accepted since the last correction");
  writeLoopOutputs(options_.output_dir, closer_, options_.global_map_voxel);
  node_.info("wrote " + options_.output_dir + "/keyframes.tum, loops.json, global_map.ply (" + summary() + "; " +
             std::to_string(closer_.graph().poses().size()) + " graph nodes, " + std::to_string(closer_.size()) +
             " keyframe clouds on disk, " + std::to_string(closer_.storedCloudBytes() / 1000000) + " MB; features of " +
             std::to_string(closer_.cachedFeatures()) + " keyframes in memory)");
}

}  // namespace livo::loop
