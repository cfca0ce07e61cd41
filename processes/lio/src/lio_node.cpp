#include "livo/lio/lio_node.hpp"

#include <chrono>
#include <iostream>

#include "livo/lio/lio_messages.hpp"
#include "livo/messages.hpp"

namespace livo::lio {

namespace {
NodeOptions nodeOptions(const LioNodeOptions& o, bool quiet) {
  NodeOptions n;
  n.name = o.name;
  n.quiet = quiet;
  return n;
}

bool finiteOdometry(const odometry_t& o) {
  return allFinite(o.position, 3) && allFinite(o.orientation, 4) && allFinite(o.velocity, 3) &&
         allFinite(o.angular_velocity, 3) && allFinite(o.pose_covariance, 36) && allFinite(o.velocity_covariance, 9) &&
         std::isfinite(o.min_information_eigenvalue);
}
}  // namespace

LioNode::LioNode(lcm::LCM& lcm, LioNodeOptions options, bool quiet)
    : opts_(std::move(options)), node_(lcm, nodeOptions(opts_, quiet)), lio_(opts_.lio) {
  node_.declareOutput(opts_.odometry_channel);
  if (opts_.publish_registered_scan) node_.declareOutput(opts_.registered_scan_channel);
  node_.declareOutput(opts_.keyframe_channel);
  node_.subscribe<imu_t>(opts_.imu_channel, [this](const imu_t& m) { onImu(m); });
  node_.subscribe<point_cloud_t>(opts_.lidar_channel, [this](const point_cloud_t& m) { onLidar(m); });
  if (opts_.lio.wheel.enabled)
    node_.subscribe<wheel_odometry_t>(opts_.wheel_channel, [this](const wheel_odometry_t& m) { onWheel(m); });
  node_.subscribe<filter_state_t>(opts_.state_posterior_channel, [this](const filter_state_t& m) { onPosterior(m); });
  node_.subscribe<loop_correction_t>(opts_.loop_correction_channel,
                                     [this](const loop_correction_t& m) { onLoopCorrection(m); });
}

void LioNode::resetAll(const std::string& why) {
  node_.warn(why + ": re-initialising");
  lio_.reset();
  imu_.clear();
  wheel_.clear();
  scans_.clear();
  has_imu_ = fed_any_imu_ = fed_any_wheel_ = false;
}

void LioNode::onImu(const imu_t& m) {
  const ImuSample s = fromMessage(m);
  if (!s.gyro.allFinite() || !s.accel.allFinite()) {
    node_.reject(opts_.imu_channel, "non-finite IMU sample");
    return;
  }
  if (fed_any_imu_ && s.utime < fed_imu_ - toUtime(opts_.clock_reset_s)) {
    resetAll("IMU time jumped back by " + std::to_string(toSeconds(fed_imu_ - s.utime)) + " s");
  }
  if ((fed_any_imu_ && s.utime <= fed_imu_) || !imu_.insert(s.utime, s)) {
    node_.reject(opts_.imu_channel, "IMU sample at or before one already used (late or duplicate)");
    return;
  }
  if (!has_imu_ || s.utime > newest_imu_) newest_imu_ = s.utime;
  has_imu_ = true;
  advance();
}

void LioNode::onLidar(const point_cloud_t& m) {
  auto p = std::make_shared<PendingScan>();
  std::string why;
  if (!fromMessage(m, &p->scan, &why)) {
    node_.reject(opts_.lidar_channel, why);
    return;
  }
  p->msg = m;
  const int64_t t_end = lio_.scanEndUtime(p->scan);
  if (lio_.initialized() && t_end <= lio_.utime()) {
    node_.reject(opts_.lidar_channel, "sweep ends before the filter time (late or duplicate)");
    return;
  }
  if (!scans_.insert(t_end, p)) {
    node_.reject(opts_.lidar_channel, "sweep older than one already processed");
    return;
  }
  while (static_cast<int>(scans_.size()) > opts_.max_pending_scans) {
    node_.warn("no IMU past pending sweeps: dropping the oldest");
    scans_.popUntil(scans_.front().utime, [](const auto&) {});
  }
  advance();
}

void LioNode::onWheel(const wheel_odometry_t& m) {
  const WheelSample w = fromMessage(m);
  if (!std::isfinite(w.left_speed) || !std::isfinite(w.right_speed)) {
    node_.reject(opts_.wheel_channel, "non-finite wheel speed");
    return;
  }
  if ((fed_any_wheel_ && w.utime <= fed_wheel_) || !wheel_.insert(w.utime, w)) {
    node_.reject(opts_.wheel_channel, "wheel reading at or before one already used");
    return;
  }
  advance();
}

void LioNode::advance() {
  // IMU: hand over everything the reorder window has settled
  if (has_imu_) {
    const int64_t settled = newest_imu_ - toUtime(opts_.imu_reorder_window_s);
    imu_.popUntil(settled, [&](const TimeBuffer<ImuSample>::Entry& e) {
      std::string why;
      if (!lio_.addImu(e.value, &why)) node_.warn("IMU sample refused by the filter: " + why);
      fed_imu_ = e.utime;
      fed_any_imu_ = true;
    });
  }
  while (!scans_.empty() && fed_any_imu_) {
    const int64_t t_end = scans_.front().utime;
    if (fed_imu_ <= t_end) break;  // no IMU past the sweep end yet
    if (opts_.lio.wheel.enabled) {
      const bool wheel_past = !wheel_.empty() && wheel_.back().utime > t_end;
      const bool waited = fed_imu_ > t_end + toUtime(opts_.wheel_max_wait_s);
      if (!wheel_past && !waited) break;
      // wheel readings up to the first one past the end
      int64_t upto = t_end;
      for (const auto& e : wheel_.entries())
        if (e.utime > t_end) {
          upto = e.utime;
          break;
        }
      wheel_.popUntil(upto, [&](const TimeBuffer<WheelSample>::Entry& e) {
        lio_.addWheel(e.value);
        fed_wheel_ = e.utime;
        fed_any_wheel_ = true;
      });
    }
    std::shared_ptr<PendingScan> p;
    scans_.popUntil(t_end, [&](const TimeBuffer<std::shared_ptr<PendingScan>>::Entry& e) {
      if (!p) {
        p = e.value;
      } else {
        node_.reject(opts_.lidar_channel, "two sweeps end at the same time: the second is dropped");
      }
    });
    process(*p);
  }
}

void LioNode::process(const PendingScan& p) {
  // The sweep is processed from whichever handler moved the IMU watermark past it: time it on its own.
  const auto t0 = std::chrono::steady_clock::now();
  ScanResult r = lio_.addScan(p.scan);
  node_.recordWork("sweep", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  ++sweeps_;
  if (!r.message.empty() && r.status != ScanResult::Status::kInitializing)
    node_.warn("sweep at " + std::to_string(p.scan.utime) + " (" + toString(r.status) + "): " + r.message);
  if (!r.hasOutput()) return;
  const odometry_t odo = toOdometry(r);
  if (!finiteOdometry(odo)) {
    node_.error("non-finite odometry withheld; re-initialising");
    lio_.reset();
    return;
  }
  node_.publish(opts_.odometry_channel, odo);
  if (opts_.publish_registered_scan) node_.publish(opts_.registered_scan_channel, toRegisteredScan(r, p.msg));
  if (r.is_keyframe) node_.publish(opts_.keyframe_channel, toKeyframe(r.keyframe, p.msg.num_rings));
}

void LioNode::onPosterior(const filter_state_t& m) {
  FilterState x;
  Mat18 P;
  if (!m.valid) return;  // the VIO kept the prior
  if (!fromFilterState(m, &x, &P)) {
    node_.reject(opts_.state_posterior_channel, "non-finite or malformed posterior");
    return;
  }
  std::string why;
  if (!lio_.adoptPosterior(m.utime, x, P, &why)) node_.reject(opts_.state_posterior_channel, why);
}

void LioNode::onLoopCorrection(const loop_correction_t& m) {
  Pose3 T;
  std::vector<LioEstimator::KeyframePose> poses;
  std::string why;
  if (!fromMessage(m, &T, &poses, &why)) {
    node_.reject(opts_.loop_correction_channel, why);
    return;
  }
  lio_.applyLoopCorrection(T, poses);
  node_.info("loop correction applied (" + std::to_string(poses.size()) + " keyframes)");
}

}  // namespace livo::lio
