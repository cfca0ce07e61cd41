#include "livo/lio_graph/lio_graph_node.hpp"

#include <chrono>
#include <sstream>

#include "livo/lio_graph/lio_graph_messages.hpp"
#include "livo/loop_correction_message.hpp"
#include "livo/sensor_messages.hpp"
#include "livo/time.hpp"

namespace livo::lio_graph {

LioGraphNode::LioGraphNode(lcm::LCM& lcm, NodeOptions node_options, LioGraphNodeOptions options)
    : node_(lcm, std::move(node_options)), options_(std::move(options)), estimator_(options_.core) {
  node_.declareOutput(options_.odometry_channel);
  node_.declareOutput(options_.registered_scan_channel);
  node_.declareOutput(options_.keyframe_channel);
  node_.subscribe<imu_t>(options_.imu_channel, [this](const imu_t& m) { onImu(m); });
  node_.subscribe<point_cloud_t>(options_.lidar_channel, [this](const point_cloud_t& m) { onLidar(m); });
  if (options_.core.use_wheel)
    node_.subscribe<wheel_odometry_t>(options_.wheel_channel, [this](const wheel_odometry_t& m) { onWheel(m); });
  node_.subscribe<loop_correction_t>(options_.loop_correction_channel,
                                     [this](const loop_correction_t& m) { onLoopCorrection(m); });
  if (options_.core.use_visual_motion)
    node_.subscribe<visual_state_t>(options_.visual_state_channel,
                                    [this](const visual_state_t& m) { onVisualState(m); });
}

void LioGraphNode::onVisualState(const visual_state_t& m) {
  std::string why;
  if (!estimator_.addVisualState(toVisualSample(m), &why)) {
    node_.reject(options_.visual_state_channel, why);
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
  const auto add = [&](std::string* w) { return estimator_.addImu(fromMessage(m), w); };
  if (!imu_.take(node_, options_.imu_channel, m.utime, add, &why)) return;
  if (estimator_.frame().epoch != epoch_before) {
    announceReset(why);
  } else if (!why.empty()) {
    node_.warn(why);
  }
  processReady();
}

void LioGraphNode::onWheel(const wheel_odometry_t& m) {
  std::string why;
  const auto add = [&](std::string* w) { return estimator_.addWheel(fromMessage(m), w); };
  if (wheel_.take(node_, options_.wheel_channel, m.utime, add, &why)) processReady();
}

void LioGraphNode::onLidar(const point_cloud_t& m) {
  PendingSweep p;
  std::string why;
  if (!fromMessage(m, &p.scan, &why)) {
    node_.reject(options_.lidar_channel, why);
    return;
  }
  p.msg = m;
  p.timing = estimator_.sweepTiming(p.scan);
  const int64_t t_end = p.timing.end_utime;
  if (!pending_.pushLater(t_end, std::move(p))) {
    node_.reject(options_.lidar_channel, "sweep does not end after the previous one");
    return;
  }
  processReady();
}

void LioGraphNode::onLoopCorrection(const loop_correction_t& m) {
  LoopCorrection correction;
  std::vector<KeyframePose> poses;
  std::string why;
  if (!fromMessage(m, &correction, &poses, &why)) {
    node_.reject(options_.loop_correction_channel, why);
    return;
  }
  if (const std::string refusal = adoptionRefusal(m, estimator_.frame()); !refusal.empty()) {
    node_.reject(options_.loop_correction_channel, refusal);
    return;
  }
  // between sweeps: the ones still waiting for the IMU are processed in the corrected frame
  estimator_.applyLoopCorrection(correction, poses);
  node_.info("loop correction " + std::to_string(m.correction_id) + " applied (" + std::to_string(poses.size()) +
             " keyframes)");
}

bool LioGraphNode::ready(int64_t t_end) const {
  if (imu_.watermark() < t_end) return false;
  if (options_.core.use_wheel && wheel_.watermark() < t_end &&
      imu_.watermark() < t_end + toUtime(options_.wheel_max_wait_s))
    return false;
  if (options_.core.use_visual_motion && estimator_.visualWatermark() < t_end &&
      imu_.watermark() < t_end + toUtime(options_.visual_max_wait_s))
    return false;
  return true;
}

void LioGraphNode::processReady() {
  pending_.popWhile([this](const PendingSweep& p) { return ready(p.timing.end_utime); },
                    [this](const PendingSweep& p) { process(p); });
}

void LioGraphNode::process(const PendingSweep& p) {
  const auto t0 = std::chrono::steady_clock::now();
  const GraphScanResult r = estimator_.addScan(p.scan, p.timing);
  node_.recordWork("sweep", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  if (!r.hasOutput()) {
    if (r.status == GraphScanResult::Status::kRejected) node_.reject(options_.lidar_channel, r.message);
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
  node_.publish(options_.odometry_channel, toOdometry(r, frame));
  node_.publish(options_.registered_scan_channel, toRegisteredScan(r, p.msg, frame));
  if (r.is_keyframe) node_.publish(options_.keyframe_channel, toKeyframe(r.keyframe, p.msg.num_rings, frame));
}

std::string LioGraphNode::summary() const {
  std::ostringstream s;
  s << processed_ << " sweeps: " << tracked_ << " tracked, " << predicted_ << " predicted only, " << degenerate_
    << " degenerate";
  if (options_.core.use_visual_motion) s << "; " << visual_ << " deskewed with the visual subsystem's motion";
  if (options_.core.use_visual_motion && options_.core.visual_factor)
    s << ", " << visual_factors_ << " with its relative-pose factor (visual scale " << estimator_.visualScale() << ")";
  if (options_.core.use_wheel && options_.core.wheel_scale_std > 0.0)
    s << "; tyre scales " << estimator_.wheelScale().x() << " (left), " << estimator_.wheelScale().y() << " (right)";
  if (estimator_.estimatesWheelMounting()) s << "; " << wheelMountingText(estimator_.wheelMounting());
  return s.str();
}

}  // namespace livo::lio_graph
