#include "livo/lio/lio_node.hpp"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>

#include "livo/file_output.hpp"
#include "livo/lio/lio_messages.hpp"
#include "livo/message_registry.hpp"
#include "livo/messages.hpp"

namespace livo::lio {

namespace {
constexpr double kWheelLogPeriodS = 30.0;  // sensor time between wheel summaries in the log
constexpr double kCalibrationRowS = 1.0;   // ... between calibration.csv rows
constexpr int kCalibrationLogRows = 10;    // ... rows between calibration lines in the log
constexpr int64_t kNever = std::numeric_limits<int64_t>::max();

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
    : options_(std::move(options)), node_(lcm, nodeOptions(options_, quiet)), lio_(options_.core) {
  node_.declareOutput(options_.odometry_channel);
  if (options_.publish_registered_scan) node_.declareOutput(options_.registered_scan_channel);
  node_.declareOutput(options_.keyframe_channel);
  node_.subscribe<imu_t>(options_.imu_channel, [this](const imu_t& m) { onImu(m); });
  node_.subscribe<point_cloud_t>(options_.lidar_channel, [this](const point_cloud_t& m) { onLidar(m); });
  if (options_.core.wheel.enabled)
    node_.subscribe<wheel_odometry_t>(options_.wheel_channel, [this](const wheel_odometry_t& m) { onWheel(m); });
  if (options_.camera_handoff) {
    node_.declareOutput(options_.state_prior_channel);
    // a VIO: it takes STATE_PRIOR and publishes STATE_POSTERIOR (a recorder of STATE_PRIOR does not)
    node_.watchConsumers(options_.state_prior_channel, 3.0, options_.state_posterior_channel);
    node_.subscribeRaw(options_.camera_channel, [this](const void* data, int size) { onCamera(data, size); });
  }
  node_.setQuietWindows([this] { return quietWindows(); });
  node_.subscribe<filter_state_t>(options_.state_posterior_channel,
                                  [this](const filter_state_t& m) { onPosterior(m); });
  node_.subscribe<loop_correction_t>(options_.loop_correction_channel,
                                     [this](const loop_correction_t& m) { onLoopCorrection(m); });
  if (options_.continue_numbering && !options_.numbering_file.empty()) {
    std::ifstream f(options_.numbering_file);
    std::string epoch_key, id_key;
    int32_t epoch = 0;
    int64_t next_id = 0;
    if (f >> epoch_key >> epoch >> id_key >> next_id && epoch_key == "epoch" && id_key == "next_keyframe_id" &&
        epoch >= 0 && next_id >= 0) {
      lio_.continueNumbering(epoch + 1, next_id);
      node_.warn("restarted: odometry goes on in epoch " + std::to_string(epoch + 1) +
                 " (a new frame), keyframe ids from " + std::to_string(next_id));
    } else {
      node_.warn("restarted, but " + options_.numbering_file + " holds no numbering: starting at epoch 0");
    }
  }
  saveNumbering();
}

void LioNode::saveNumbering() {
  if (options_.numbering_file.empty()) return;
  const std::string text = "epoch " + std::to_string(lio_.frame().epoch) + "\nnext_keyframe_id " +
                           std::to_string(lio_.nextKeyframeId()) + "\n";
  std::string error;
  if (!writeFileAtomically(options_.numbering_file, {text}, &error)) node_.warn("cannot keep the numbering: " + error);
}

void LioNode::resetAll(const std::string& why) {
  lio_.reset();
  announceReset(why);
  imu_.clear();
  wheel_.clear();
  scans_.clear();
  images_.clear();
  newest_sweep_end_ = last_image_ = newest_image_ = -1;
  pending_.reset();
  held_jump_.reset();
  has_imu_ = fed_any_imu_ = fed_any_wheel_ = false;
}

void LioNode::announceReset(const std::string& why) {
  ++resets_;
  saveNumbering();  // before anything of the new epoch is published (as for keyframes)
  node_.warn("odometry reset to epoch " + std::to_string(lio_.frame().epoch) + ": " + why + ": re-initialising");
  node_.publishHealthNow();  // the reason reaches resets.json / report.md even if a warning follows
}

void LioNode::onImu(const imu_t& m) {
  const ImuSample s = fromMessage(m);
  if (!s.gyro.allFinite() || !s.accel.allFinite()) {
    node_.reject(options_.imu_channel, "non-finite IMU sample");
    return;
  }
  if (s.gyro.norm() > options_.imu_max_angular_velocity || s.accel.norm() > options_.imu_max_acceleration) {
    node_.reject(options_.imu_channel,
                 "IMU sample beyond the sensor's range (imu_max_angular_velocity, "
                 "imu_max_acceleration): corrupted");
    return;
  }
  // A stamp that jumps (ahead by clock_jump_s or back by clock_reset_s) is held until the next
  // sample confirms the new clock by following it closely; otherwise it was one corrupted stamp.
  if (has_imu_) {
    const bool jumps = s.utime > newest_imu_ + toUtime(options_.clock_jump_s) ||
                       s.utime < newest_imu_ - toUtime(options_.clock_reset_s);
    const bool confirms =
        held_jump_ && s.utime > held_jump_->utime && s.utime - held_jump_->utime <= toUtime(options_.clock_jump_s);
    if (jumps && !confirms) {
      if (held_jump_)
        node_.reject(options_.imu_channel, "an IMU stamp that jumped was not confirmed: dropped as corrupted");
      held_jump_ = s;
      node_.reject(options_.imu_channel, "IMU stamp jumps by " + std::to_string(toSeconds(s.utime - newest_imu_)) +
                                             " s: held until the next sample confirms the new clock");
      return;
    }
    if (held_jump_) {
      const ImuSample first = *held_jump_;
      held_jump_.reset();
      if (jumps) {
        acceptImu(first);
      } else {
        node_.reject(options_.imu_channel, "an IMU stamp that jumped was not confirmed: dropped as corrupted");
      }
    }
  }
  acceptImu(s);
}

void LioNode::acceptImu(const ImuSample& s) {
  if (fed_any_imu_ && s.utime < fed_imu_ - toUtime(options_.clock_reset_s)) {
    resetAll("IMU time jumped back by " + std::to_string(toSeconds(fed_imu_ - s.utime)) + " s");
  }
  if ((fed_any_imu_ && s.utime <= fed_imu_) || !imu_.insert(s.utime, s)) {
    node_.reject(options_.imu_channel, "IMU sample at or before one already used (late or duplicate)");
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
    node_.reject(options_.lidar_channel, why);
    return;
  }
  p->format = sweepFormat(m);
  p->timing = lio_.sweepTiming(p->scan);
  const int64_t t_end = p->timing.end_utime;
  // Refused on arrival if the filter is already past its end. addScan asks again when its turn
  // comes: the filter may have moved meanwhile (a duplicate queued beside it ends where the first
  // left the filter), and before the map is seeded it refuses sweeps of the IMU start-up window.
  if (!lio_.acceptsSweepEnding(t_end)) {
    node_.reject(options_.lidar_channel, "sweep ends before the filter time (late or duplicate)");
    return;
  }
  if (!scans_.insert(t_end, p)) {
    node_.reject(options_.lidar_channel, "sweep older than one already processed");
    return;
  }
  newest_sweep_end_ = std::max(newest_sweep_end_, t_end);
  while (static_cast<int>(scans_.size()) > options_.max_pending_scans) {
    node_.warn("no IMU past pending sweeps: dropping the oldest");
    scans_.popUntil(scans_.front().utime, [](const auto&) {});
  }
  advance();
}

void LioNode::onCamera(const void* data, int size) {
  // only the image time matters here: read the leading utime without decoding the pixels
  const MessageType* type = identifyMessage(data, size);
  int64_t utime = 0;
  if (!type || type->name != "livo.image_t" || !messageUtime(data, size, &utime)) {
    node_.reject(options_.camera_channel, "not a livo.image_t message");
    return;
  }
  node_.noteSensorTime(utime);
  const int64_t t = utime + toUtime(options_.camera_time_offset_s);
  newest_image_ = std::max(newest_image_, t);
  if ((lio_.initialized() && t < lio_.utime()) || t <= last_image_ || (pending_ && t <= pending_->utime)) {
    ++handoff_.images_skipped;  // the filter is already past it
    return;
  }
  images_.insert(t, true);
  while (static_cast<int>(images_.size()) > options_.max_pending_scans) {
    ++handoff_.images_skipped;  // no IMU past them: the oldest are dropped like sweeps are
    images_.popUntil(images_.front().utime, [](const auto&) {});
  }
  advance();
}

void LioNode::onWheel(const wheel_odometry_t& m) {
  const WheelSample w = fromMessage(m);
  if (!std::isfinite(w.left_speed) || !std::isfinite(w.right_speed)) {
    node_.reject(options_.wheel_channel, "non-finite wheel speed");
    return;
  }
  if ((fed_any_wheel_ && w.utime <= fed_wheel_) || !wheel_.insert(w.utime, w)) {
    node_.reject(options_.wheel_channel, "wheel reading at or before one already used");
    return;
  }
  advance();
}

void LioNode::advance() {
  // IMU: hand over everything the reorder window has settled
  if (has_imu_) {
    const int64_t settled = newest_imu_ - toUtime(options_.imu_reorder_window_s);
    imu_.popUntil(settled, [&](const TimeBuffer<ImuSample>::Entry& e) {
      std::string why;
      if (!lio_.addImu(e.value, &why)) node_.warn("IMU sample refused by the filter: " + why);
      fed_imu_ = e.utime;
      fed_any_imu_ = true;
    });
  }
  // wheel readings no pending sweep can need (a LiDAR outage must not grow the buffer)
  if (fed_any_imu_) wheel_.dropBefore(fed_imu_ - toUtime(options_.wheel_max_wait_s + 1.0));
  while (fed_any_imu_) {
    if (pending_) {
      // waiting for the posterior of an image: nothing later may be processed meanwhile
      const bool vio_gone = !node_.hasConsumers(options_.state_prior_channel);
      if (!vio_gone && fed_imu_ <= pending_->utime + toUtime(options_.posterior_max_wait_s)) break;
      ++handoff_.missing;
      node_.warn("no STATE_POSTERIOR for the image at " + std::to_string(pending_->utime) + ": going on LiDAR-only (" +
                 std::to_string(handoff_.missing) + " so far)");
      pending_.reset();
    }
    const NextEvent next = nextEvent();
    if (next.kind == NextEvent::kNone || fed_imu_ <= next.imu_after) break;
    if (next.kind == NextEvent::kImage) {
      images_.popUntil(next.utime, [](const auto&) {});
      handOff(next.utime);
      continue;
    }
    const int64_t t_end = next.utime;
    if (options_.core.wheel.enabled) {
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
        node_.reject(options_.lidar_channel, "two sweeps end at the same time: the second is dropped");
      }
    });
    process(*p);
  }
}

LioNode::NextEvent LioNode::nextEvent() const {
  NextEvent e;
  // the earlier of the next image time and the next sweep end; a sweep ending at the image first
  if (!images_.empty() && (scans_.empty() || images_.front().utime < scans_.front().utime)) {
    e.kind = NextEvent::kImage;
    e.utime = e.imu_after = images_.front().utime;
    // every sweep ending at or before the image must have been processed (the LiDAR watermark)
    const bool lidar_past = newest_sweep_end_ >= e.utime;
    if (!lidar_past) e.imu_after += toUtime(options_.image_lidar_wait_s);
    return e;
  }
  if (scans_.empty()) return e;
  e.kind = NextEvent::kSweep;
  e.utime = e.imu_after = scans_.front().utime;
  if (options_.core.wheel.enabled) {
    const bool wheel_past = !wheel_.empty() && wheel_.back().utime > e.utime;
    if (!wheel_past) e.wheel_wait = toUtime(options_.wheel_max_wait_s);
  }
  if (options_.camera_handoff && newest_image_ >= 0 && e.utime - newest_image_ < toUtime(1.0) &&
      node_.hasConsumers(options_.state_prior_channel)) {
    // the images before the sweep end come first: wait until the next one is due after it
    const bool images_past = newest_image_ + toUtime(0.75 / options_.camera_rate_hz) > e.utime;
    if (!images_past) e.image_wait = toUtime(options_.image_max_wait_s);
  }
  e.imu_after = e.utime + std::max(e.wheel_wait, e.image_wait);
  return e;
}

LioNode::Promises LioNode::promises(const NextEvent& next) const {
  // advance() acts only once the filter's newest sample is past the next event's threshold, and
  // the filter gets samples imu_reorder_window_s behind the newest received. Images and sweeps
  // may be promised too: an image stamped at or after image_due, a sweep ending at or after the
  // newest sweep end, becomes an event whose threshold is not below that time; and it may lower
  // the next event's threshold only by ending its wait for images (a sweep) or for the LiDAR (an
  // image); wheel readings only by ending a sweep's wait for them. The lowest threshold covered
  // messages can bring about is the floor below; they
  // cannot make advance() act, in any interleaving, provided the filter is not past the floor and
  // the IMU promise ends there too (the filter then stays at or before it).
  // image_due is where the next image is due, so that the IMU up to where it is handed off stays
  // covered; an earlier image is not covered (playback then waits for lio once, which is merely
  // slower). No image promise before the first image, nor once the next is a period overdue (a
  // camera that stopped must not hold the IMU promise back). Sweeps are promised where they
  // arrive before the IMU passes the newest sweep end (a driver that stamps and sends a sweep at
  // its start, or soon after its end).
  Promises p;
  p.period = toUtime(1.0 / options_.camera_rate_hz);
  p.image_due = newest_image_ + p.period;
  const bool images_possible = options_.camera_handoff && newest_image_ >= 0 && newest_imu_ <= p.image_due + p.period;
  const bool sweeps_possible = newest_sweep_end_ >= 0;
  const bool wheels_possible = options_.core.wheel.enabled;
  const auto floor = [&](bool images, bool sweeps, bool wheels) {
    int64_t f = kNever;
    if (next.kind == NextEvent::kImage) f = sweeps ? next.utime : next.imu_after;
    if (next.kind == NextEvent::kSweep)
      f = next.utime + std::max(images ? 0 : next.image_wait, wheels ? 0 : next.wheel_wait);
    if (images) f = std::min(f, p.image_due);
    if (sweeps) f = std::min(f, newest_sweep_end_);
    return f;
  };
  // the most channels whose floor the filter is not past (a covered message could act at once)
  for (int mask = 7; mask > 0; --mask) {
    const bool i = mask & 4, s = mask & 2, w = mask & 1;
    if ((i && !images_possible) || (s && !sweeps_possible) || (w && !wheels_possible)) continue;
    if (fed_any_imu_ && floor(i, s, w) < fed_imu_) continue;
    p.images = i;
    p.sweeps = s;
    p.wheels = w;
    break;
  }
  p.threshold = floor(p.images, p.sweeps, p.wheels);
  // Waiting for a posterior: advance() also acts once the filter is posterior_max_wait_s past the
  // image (it gives up on the answer), and the filter propagates on its own once its IMU queue
  // spans max_imu_backlog_s (the posterior could then not be adopted): the promises end before.
  if (pending_) {
    p.threshold = std::min(p.threshold, pending_->utime + toUtime(options_.posterior_max_wait_s));
    if (const int64_t queued = lio_.oldestQueuedImu(); queued != kNever)
      p.threshold = std::min(p.threshold, queued + toUtime(options_.core.max_imu_backlog_s));
  }
  return p;
}

std::vector<Node::QuietWindow> LioNode::quietWindows() const {
  // waiting for the next sample to confirm a jumped clock: no promise; nor while a posterior is
  // out with no vio there to answer it (advance() then gives up on it at the next sample)
  if (!has_imu_ || held_jump_ || (pending_ && !node_.hasConsumers(options_.state_prior_channel))) return {};
  const NextEvent next = nextEvent();
  const Promises p = promises(next);

  Node::QuietWindow w;
  w.channel = options_.imu_channel;
  // a sample further back is a clock reset, one further ahead is held as a jump
  w.from = newest_imu_ - toUtime(options_.clock_reset_s);
  w.before = newest_imu_ + toUtime(options_.clock_jump_s);
  if (p.threshold != kNever) w.before = std::min(w.before, p.threshold + toUtime(options_.imu_reorder_window_s) + 1);
  std::vector<Node::QuietWindow> out{w};
  // The posterior being waited for: adopting it publishes nothing while the filter is not past the
  // next event's threshold (covered messages keep it there), and it commutes with the covered IMU
  // samples, which only join the filter's queue after the image time it sets the state at. So
  // lockstep playback may send them while vio is still working on the image.
  if (pending_ && (!fed_any_imu_ || fed_imu_ <= p.threshold))
    out.push_back(Node::QuietWindow::always(options_.state_posterior_channel));
  // in the messages' own clocks; a period's worth of images (several in one window are as safe)
  if (p.images) {
    const int64_t offset = toUtime(options_.camera_time_offset_s);
    out.push_back({options_.camera_channel, p.image_due - offset, p.image_due + p.period - offset});
  }
  if (p.sweeps) {
    // a sweep ends at or after its stamp plus the LiDAR's time offset
    const int64_t offset = toUtime(options_.core.extrinsics.time_offset_s);
    out.push_back({options_.lidar_channel, newest_sweep_end_ - offset, kNever});
  }
  if (p.wheels) {
    out.push_back(Node::QuietWindow::always(options_.wheel_channel));
  } else if (options_.core.wheel.enabled) {
    // the filter is past the sweep's end and it waits for the wheels: a reading past its end would
    // let it go; readings up to its end cannot
    const bool sweep_waits_for_wheels =
        next.kind == NextEvent::kSweep && !(!wheel_.empty() && wheel_.back().utime > next.utime);
    if (sweep_waits_for_wheels)
      out.push_back({options_.wheel_channel, std::numeric_limits<int64_t>::min(), next.utime + 1});
    else
      out.push_back(Node::QuietWindow::always(options_.wheel_channel));
  }
  return out;
}

void LioNode::process(const PendingScan& p) {
  // The sweep is processed from whichever handler moved the IMU watermark past it: time it on its own.
  const auto t0 = std::chrono::steady_clock::now();
  const int32_t epoch_before = lio_.frame().epoch;
  ScanResult r = lio_.addScan(p.scan, p.timing);
  if (lio_.frame().epoch != epoch_before) announceReset(r.message.empty() ? "the filter re-initialised" : r.message);
  node_.recordWork("sweep", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  ++sweeps_;
  if (!r.message.empty() && r.status != ScanResult::Status::kInitializing)
    node_.warn("sweep at " + std::to_string(p.scan.utime) + " (" + toString(r.status) + "): " + r.message);
  if (options_.core.wheel.enabled && r.utime - last_wheel_log_ >= toUtime(kWheelLogPeriodS)) {
    if (last_wheel_log_ != 0) node_.info(wheelSummary());
    last_wheel_log_ = r.utime;
  }
  if (r.hasOutput()) reportCalibration(r.utime);
  if (!r.hasOutput()) return;
  const odometry_t odo = toOdometry(r, lio_.frame());
  if (!finiteOdometry(odo)) {
    node_.error("non-finite odometry withheld");
    lio_.reset();
    announceReset("non-finite odometry");
    return;
  }
  node_.publish(options_.odometry_channel, odo);
  ++sweep_counts_.published;
  sweep_counts_.tracked += r.status == ScanResult::Status::kTracked;
  sweep_counts_.predicted += r.status == ScanResult::Status::kPredicted;
  sweep_counts_.degenerate += odo.degenerate != 0;
  if (options_.publish_registered_scan)
    node_.publish(options_.registered_scan_channel, toRegisteredScan(r, p.scan, p.format, lio_.frame()));
  if (r.is_keyframe) {
    // the numbering on disk first: a process killed between the two then skips an id on restart
    // instead of repeating the one it published (livo-loop refuses a repeated id)
    saveNumbering();
    node_.publish(options_.keyframe_channel, toKeyframe(r.keyframe, p.format.num_rings, lio_.frame()));
  }
}

std::string LioNode::sweepSummary() const {
  const SweepCounts& c = sweep_counts_;
  return "odometry of " + std::to_string(c.published) + " sweeps: " + std::to_string(c.tracked) + " tracked, " +
         std::to_string(c.predicted) + " predicted without a LiDAR update, " + std::to_string(c.degenerate) +
         " degenerate (report.md: \"Where the estimate was weak\")";
}

bool LioNode::estimatesCalibration() const {
  CalibrationStd lidar, camera;
  calibrationPrior(options_.core.lidar_calibration_std, options_.core.camera_calibration_std, options_.core.calibration,
                   &lidar, &camera);
  return lidar.any() || (options_.camera_handoff && camera.any());
}

CalibrationEstimate LioNode::calibrationEstimate() const {
  return calibrationAgainstRig(lio_.state(), lio_.covariance(), options_.core.extrinsics.T_I_L,
                               options_.core.camera_T_I_C);
}

std::string LioNode::calibrationSummary() const {
  if (!lio_.initialized()) return "";
  std::string text = "calibration: " + describe(calibrationEstimate(), options_.camera_handoff);
  if (lio_.modelsImuIntrinsics())
    text += "; " + describeImuIntrinsics(lio_.imuIntrinsics(), lio_.imuIntrinsicsCovariance());
  return text;
}

void LioNode::reportCalibration(int64_t utime) {
  if (!estimatesCalibration() || utime - last_calibration_log_ < toUtime(kCalibrationRowS)) return;
  if (calibration_csv_.empty()) {
    calibration_csv_ = calibrationCsvHeader();
    calibration_t0_ = utime;
  }
  calibration_csv_ += calibrationCsvRow(toSeconds(utime - calibration_t0_), calibrationEstimate());
  if (++calibration_rows_ % kCalibrationLogRows == 0) node_.info(calibrationSummary());
  last_calibration_log_ = utime;
}

void LioNode::writeCalibrationFiles() {
  if (options_.output_dir.empty() || !estimatesCalibration() || !lio_.initialized()) return;
  const CalibrationEstimate e = calibrationEstimate();
  std::string error;
  const std::string csv = options_.output_dir + "/calibration.csv", yaml = options_.output_dir + "/calibration.yaml";
  if (!writeFileAtomically(csv, {calibration_csv_.empty() ? calibrationCsvHeader() : calibration_csv_}, &error) ||
      !writeFileAtomically(yaml,
                           {calibrationOverlay(lio_.state(), options_.core.extrinsics.time_offset_s,
                                               options_.camera_time_offset_s, options_.camera_handoff, e)},
                           &error))
    node_.error("calibration files: " + error);
  else
    node_.info("wrote " + csv + " and " + yaml);
}

std::string LioNode::wheelSummary() const {
  const LioEstimator::WheelCounts& n = lio_.wheelCounts();
  std::ostringstream os;
  os << "wheel updates: " << n.accepted << " accepted, " << n.rejected << " rejected (chi2 gate), " << n.no_reading
     << " without a reading; ";
  if (!options_.core.wheel_scale.enabled) {
    os << "scale calibration off";
    return os.str();
  }
  const WheelScaleEstimator& s = lio_.wheelScale();
  const WheelScaleEstimator::Counts& c = s.counts();
  os << std::fixed << std::setprecision(4) << "scales left " << s.scales().x() << " +/- " << s.stds().x() << ", right "
     << s.scales().y() << " +/- " << s.stds().y() << " (" << c.learned << " intervals learnt from, " << c.outliers
     << " gated as slip, " << c.unobservable << " unobservable)";
  return os.str();
}

void LioNode::handOff(int64_t utime) {
  const bool repeated = utime <= last_image_;
  last_image_ = std::max(last_image_, utime);
  if (!lio_.tracking() || utime < lio_.utime() || repeated) {
    ++handoff_.images_skipped;
    return;
  }
  if (!node_.hasConsumers(options_.state_prior_channel)) {
    ++handoff_.no_vio;  // nobody would answer: LiDAR-only, exactly as without the hand-off
    return;
  }
  std::string note;
  if (!lio_.propagateTo(utime, &note)) {
    resetAll("propagation to the image time failed" + (note.empty() ? std::string() : " (" + note + ")"));
    return;
  }
  if (!note.empty()) node_.warn("image at " + std::to_string(utime) + ": " + note);
  const int64_t id = next_request_id_++;
  node_.publish(options_.state_prior_channel, toStatePrior(lio_, utime, id, options_.name));
  ++handoff_.priors;
  pending_ = PendingPrior{id, utime};
}

void LioNode::onPosterior(const filter_state_t& m) {
  if (m.epoch != lio_.frame().epoch) {
    node_.reject(options_.state_posterior_channel,
                 "posterior for odometry epoch " + std::to_string(m.epoch) + ", the filter is in epoch " +
                     std::to_string(lio_.frame().epoch) + " (made before a reset): ignored");
    return;
  }
  if (!pending_ || m.request_id != pending_->request_id || m.utime != pending_->utime) {
    node_.reject(options_.state_posterior_channel, "posterior answers no waiting prior (late, duplicate or foreign)");
    return;
  }
  pending_.reset();
  FilterState x;
  StateCovariance P;
  std::string why;
  if (!m.valid) {
    ++handoff_.kept_prior;  // the VIO kept the prior (it says why on its own HEALTH)
  } else if (!fromFilterState(m, &x, &P)) {
    ++handoff_.kept_prior;
    node_.reject(options_.state_posterior_channel, "non-finite or malformed posterior: prior kept");
  } else if (!lio_.adoptPosterior(m.utime, x, P, &why)) {
    ++handoff_.kept_prior;
    node_.reject(options_.state_posterior_channel, why + ": prior kept");
  } else {
    ++handoff_.adopted;
  }
  advance();
}

void LioNode::onLoopCorrection(const loop_correction_t& m) {
  LioEstimator::LoopCorrection correction;
  std::vector<LioEstimator::KeyframePose> poses;
  std::string why;
  if (!fromMessage(m, &correction, &poses, &why)) {
    node_.reject(options_.loop_correction_channel, why);
    return;
  }
  if (const std::string refusal = adoptionRefusal(m, lio_.frame()); !refusal.empty()) {
    node_.reject(options_.loop_correction_channel, refusal);
    return;
  }
  if (pending_) {
    node_.warn("loop correction while an image prior is out: its posterior will be ignored");
    ++handoff_.missing;
    pending_.reset();
  }
  lio_.applyLoopCorrection(correction, poses);
  node_.info("loop correction " + std::to_string(m.correction_id) + " applied (" + std::to_string(poses.size()) +
             " keyframes)");
  advance();
}

}  // namespace livo::lio
