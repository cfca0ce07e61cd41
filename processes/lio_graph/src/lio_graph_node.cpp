#include "livo/lio_graph/lio_graph_node.hpp"

#include <chrono>
#include <sstream>

#include "livo/lio_graph/lio_graph_messages.hpp"
#include "livo/loop_correction_message.hpp"
#include "livo/sensor_messages.hpp"
#include "livo/time.hpp"

namespace livo::lio_graph {

LioGraphNode::LioGraphNode(lcm::LCM& lcm, NodeOptions node_options, LioGraphNodeOptions options)
    : node_(lcm, std::move(node_options)), opts_(std::move(options)), estimator_(opts_.core) {
  node_.declareOutput(opts_.odometry_channel);
  node_.declareOutput(opts_.registered_scan_channel);
  node_.declareOutput(opts_.keyframe_channel);
  node_.subscribe<imu_t>(opts_.imu_channel, [this](const imu_t& m) { onImu(m); });
  node_.subscribe<point_cloud_t>(opts_.lidar_channel, [this](const point_cloud_t& m) { onLidar(m); });
  if (opts_.core.use_wheel)
    node_.subscribe<wheel_odometry_t>(opts_.wheel_channel, [this](const wheel_odometry_t& m) { onWheel(m); });
  node_.subscribe<loop_correction_t>(opts_.loop_correction_channel,
                                     [this](const loop_correction_t& m) { onLoopCorrection(m); });
  if (opts_.core.use_visual_motion)
    node_.subscribe<visual_state_t>(opts_.visual_state_channel, [this](const visual_state_t& m) { onVisualState(m); });
}

void LioGraphNode::onVisualState(const visual_state_t& m) {
  std::string why;
  if (!estimator_.addVisualState(toVisualSample(m), &why)) {
    node_.reject(opts_.visual_state_channel, why);
    return;
  }
  processReady();
}

void LioGraphNode::announceReset(const std::string& why) {
  ++resets_;
  node_.warn("odometry reset to epoch " + std::to_string(estimator_.frame().epoch) + ": " + why + ": re-initialising");
  node_.publishHealthNow();  // the reason reaches resets.json / report.md even if a warning follows
}

void LioGraphNode::onImu(const imu_t& m) {
  std::string why;
  const int32_t epoch_before = estimator_.frame().epoch;
  if (!estimator_.addImu(fromMessage(m), &why)) {
    node_.reject(opts_.imu_channel, why);
    return;
  }
  if (estimator_.frame().epoch != epoch_before) {
    announceReset(why);
  } else if (!why.empty()) {
    node_.warn(why);
  }
  imu_watermark_ = m.utime;
  processReady();
}

void LioGraphNode::onWheel(const wheel_odometry_t& m) {
  std::string why;
  if (!estimator_.addWheel(fromMessage(m), &why)) {
    node_.reject(opts_.wheel_channel, why);
    return;
  }
  wheel_watermark_ = m.utime;
  processReady();
}

void LioGraphNode::onLidar(const point_cloud_t& m) {
  PendingSweep p;
  std::string why;
  if (!fromMessage(m, &p.scan, &why)) {
    node_.reject(opts_.lidar_channel, why);
    return;
  }
  p.msg = m;
  p.timing = estimator_.sweepTiming(p.scan);
  if (!pending_.empty() && p.timing.end_utime <= pending_.back().timing.end_utime) {
    node_.reject(opts_.lidar_channel, "sweep does not end after the previous one");
    return;
  }
  pending_.push_back(std::move(p));
  processReady();
}

void LioGraphNode::onLoopCorrection(const loop_correction_t& m) {
  LoopCorrection correction;
  std::vector<KeyframePose> poses;
  std::string why;
  if (!fromMessage(m, &correction, &poses, &why)) {
    node_.reject(opts_.loop_correction_channel, why);
    return;
  }
  if (const std::string refusal = adoptionRefusal(m, estimator_.frame()); !refusal.empty()) {
    node_.reject(opts_.loop_correction_channel, refusal);
    return;
  }
  // between sweeps: the ones still waiting for the IMU are processed in the corrected frame
  estimator_.applyLoopCorrection(correction, poses);
  node_.info("loop correction " + std::to_string(m.correction_id) + " applied (" + std::to_string(poses.size()) +
             " keyframes)");
}

void LioGraphNode::processReady() {
  while (!pending_.empty()) {
    const PendingSweep& p = pending_.front();
    const int64_t t_end = p.timing.end_utime;
    if (imu_watermark_ < t_end) return;
    if (opts_.core.use_wheel && wheel_watermark_ < t_end && imu_watermark_ < t_end + toUtime(opts_.wheel_max_wait_s))
      return;
    if (opts_.core.use_visual_motion && estimator_.visualWatermark() < t_end &&
        imu_watermark_ < t_end + toUtime(opts_.visual_max_wait_s))
      return;
    process(p);
    pending_.pop_front();
  }
}

void LioGraphNode::process(const PendingSweep& p) {
  const auto t0 = std::chrono::steady_clock::now();
  const GraphScanResult r = estimator_.addScan(p.scan, p.timing);
  node_.recordWork("sweep", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  if (!r.hasOutput()) {
    if (r.status == GraphScanResult::Status::kRejected) node_.reject(opts_.lidar_channel, r.message);
    return;
  }
  ++processed_;
  tracked_ += r.status == GraphScanResult::Status::kTracked;
  predicted_ += r.status == GraphScanResult::Status::kPredicted;
  degenerate_ += r.degenerate;
  visual_ += r.visual_motion;
  visual_factors_ += r.visual_factor;
  if (!r.message.empty()) node_.info(r.message);
  const OdometryFrame& frame = estimator_.frame();
  node_.publish(opts_.odometry_channel, toOdometry(r, frame));
  node_.publish(opts_.registered_scan_channel, toRegisteredScan(r, p.msg, frame));
  if (r.is_keyframe) node_.publish(opts_.keyframe_channel, toKeyframe(r.keyframe, p.msg.num_rings, frame));
}

std::string LioGraphNode::summary() const {
  std::ostringstream s;
  s << processed_ << " sweeps: " << tracked_ << " tracked, " << predicted_ << " predicted only, " << degenerate_
    << " degenerate";
  if (opts_.core.use_visual_motion) s << "; " << visual_ << " deskewed with the visual subsystem's motion";
  if (opts_.core.use_visual_motion && opts_.core.visual_factor)
    s << ", " << visual_factors_ << " with its relative-pose factor (visual scale " << estimator_.visualScale() << ")";
  if (opts_.core.use_wheel && opts_.core.wheel_scale_std > 0.0)
    s << "; tyre scales " << estimator_.wheelScale().x() << " (left), " << estimator_.wheelScale().y() << " (right)";
  if (estimator_.estimatesWheelMounting()) s << "; " << wheelMountingText(estimator_.wheelMounting());
  return s.str();
}

}  // namespace livo::lio_graph
