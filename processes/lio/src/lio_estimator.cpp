#include "livo/lio/lio_estimator.hpp"

#include <optional>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "livo/lio/scan_to_map.hpp"
#include "livo/lio/undistorter.hpp"
#include "livo/result_note.hpp"
#include "livo/text_format.hpp"
#include "livo/time.hpp"

namespace livo::lio {

namespace {

/// The points registered against the map: every point_stride-th, then one per scan voxel.
std::vector<Vec3> registrationSubset(const std::vector<Vec3>& body, int point_stride, double scan_voxel_size) {
  const size_t stride = static_cast<size_t>(std::max(1, point_stride));
  std::vector<size_t> subset;
  if (stride == 1) {
    subset = firstPointPerVoxel(body, scan_voxel_size);
  } else {
    for (size_t i = 0; i < body.size(); i += stride) subset.push_back(i);
    subset = firstPointPerVoxel(body, subset, scan_voxel_size);
  }
  std::vector<Vec3> reg;
  for (size_t i : subset) reg.push_back(body[i]);
  return reg;
}

/// The sweep's points in the world at the posterior x, with their indices in the input sweep.
void worldPoints(const std::vector<Vec3>& body, const std::vector<size_t>& valid, const FilterState& x,
                 ScanResult* res) {
  res->world_points.resize(body.size());
  res->input_index.resize(body.size());
  for (size_t i = 0; i < body.size(); ++i) {
    res->input_index[i] = static_cast<uint32_t>(valid[i]);
    res->world_points[i] = x.rot * body[i] + x.pos;
  }
}
}  // namespace

const char* toString(ScanResult::Status s) {
  switch (s) {
    case ScanResult::Status::kInitializing: return "initializing";
    case ScanResult::Status::kRejected: return "rejected";
    case ScanResult::Status::kMapInitialized: return "map initialized";
    case ScanResult::Status::kTracked: return "tracked";
    case ScanResult::Status::kPredicted: return "predicted";
  }
  return "?";
}

LioEstimator::LioEstimator(LioOptions options)
    : options_(options),
      prop_(options.imu_noise),
      map_(options.map),
      planes_(options.planes),
      search_threads_(options.search_threads > 1 ? std::make_shared<WorkerThreads>(options.search_threads) : nullptr),
      keyframe_selector_(options.keyframe),
      wheel_scale_(options.wheel_scale, options.wheel.speed_noise_std) {
  if (options_.calibration.imu_axes != CalibrationEstimation::ImuAxes::kBudget)
    prop_.setIntrinsics({}, intrinsicsPrior(options_.imu_noise), estimatesImuAxes());
}

Vec3 LioEstimator::nominalGyro(const FilterState& x) const {
  // the reading a sensor with the nominal axes would have given: its rate minus the bias is the
  // corrected rate
  return prop_.angularVelocity(prop_.lastSample().gyro, x) + x.gyro_bias;
}

void LioEstimator::reset() {
  if (initialized_ && prop_.state().lidar.rot.allFinite() && prop_.state().camera.rot.allFinite() &&
      prop_.covariance().bottomRightCorner<14, 14>().allFinite()) {
    // the calibration belongs to the rig, not to an odometry epoch: the next one starts from it
    kept_calibration_ = prop_.state();
    kept_calibration_cov_ = prop_.covariance();
    has_kept_calibration_ = true;
  }
  frame_ = OdometryFrame{frame_.epoch + 1, 0, Pose3::Identity()};
  // the IMU's axes belong to the sensor too: kept when finite
  const ImuIntrinsics intrinsics = prop_.intrinsics();
  const ImuIntrinsics::Covariance intrinsics_cov = prop_.intrinsicsCovariance();
  const bool keep_intrinsics = prop_.modelsIntrinsics() && intrinsics.value.allFinite() && intrinsics_cov.allFinite();
  prop_ = ImuPropagator(options_.imu_noise);
  if (keep_intrinsics)
    prop_.setIntrinsics(intrinsics, intrinsics_cov, estimatesImuAxes());
  else if (options_.calibration.imu_axes != CalibrationEstimation::ImuAxes::kBudget)
    prop_.setIntrinsics({}, intrinsicsPrior(options_.imu_noise), estimatesImuAxes());
  map_.clear();
  planes_.clear();
  keyframe_selector_.reset();
  initialized_ = false;
  init_window_.clear();
  imu_.clear();
  wheel_.clear();
  has_imu_ = has_wheel_ = false;
  has_scale_anchor_ = false;
  keyframes_.clear();
  clone_ = KeyframeClone{};
  last_registered_body_.clear();
  has_last_post_ = has_prev_post_ = false;
  has_registered_ = false;
  last_sweep_end_utime_ = -1;
}

bool LioEstimator::addImu(const ImuSample& s, std::string* why) {
  if (!s.gyro.allFinite() || !s.accel.allFinite()) {
    if (why) *why = "non-finite IMU sample";
    return false;
  }
  if (has_imu_ && s.utime <= last_imu_utime_) {
    if (why) *why = "IMU sample not later than the previous one";
    return false;
  }
  has_imu_ = true;
  last_imu_utime_ = s.utime;
  if (initialized_) {
    imu_.push_back(s);
    // no sweep has come for a while: propagate the backlog now, keeping half of it for a late
    // sweep, and forget the undistortion segments no sweep can need any more
    if (imu_.front().utime < s.utime - toUtime(options_.max_imu_backlog_s)) drainBacklog(s.utime);
  } else {
    init_window_.push_back(s);
    tryInitialize(nullptr);
  }
  return true;
}

bool LioEstimator::addWheel(const WheelSample& s, std::string* why) {
  if (!options_.wheel.enabled) {
    if (why) *why = "wheel fusion is disabled";
    return false;
  }
  if (!std::isfinite(s.left_speed) || !std::isfinite(s.right_speed)) {
    if (why) *why = "non-finite wheel speed";
    return false;
  }
  if (has_wheel_ && s.utime <= last_wheel_utime_) {
    if (why) *why = "wheel reading not later than the previous one";
    return false;
  }
  has_wheel_ = true;
  last_wheel_utime_ = s.utime;
  wheel_.push_back(s);
  return true;
}

void LioEstimator::tryInitialize(std::string* note) {
  if (init_window_.size() < 2) return;
  const int64_t span = init_window_.back().utime - init_window_.front().utime;
  // a gap inside the window restarts it
  const int64_t last_gap = init_window_.back().utime - init_window_[init_window_.size() - 2].utime;
  if (static_cast<double>(last_gap) * 1e-6 > options_.max_imu_gap_s) {
    init_window_.erase(init_window_.begin(), init_window_.end() - 1);
    return;
  }
  if (static_cast<double>(span) * 1e-6 < options_.init.window_s) return;
  const ImuInitResult r = initializeImu(init_window_, options_.init);
  if (!r.ok) {
    appendNote(note, "IMU initialisation: " + r.message);
    // slide the window by half its length
    const int64_t cut = init_window_.back().utime - toUtime(0.5 * options_.init.window_s);
    init_window_.erase(init_window_.begin(), std::find_if(init_window_.begin(), init_window_.end(),
                                                          [&](const ImuSample& s) { return s.utime >= cut; }));
    return;
  }
  prop_.reset(initialState(r), initialCovariance(r), r.last);
  initialized_ = true;
  init_window_.clear();
  imu_.clear();
  last_prune_position_ = r.state.pos;
}

void calibrationPrior(const CalibrationStd& l, const CalibrationStd& c, const CalibrationEstimation& e,
                      CalibrationStd* lidar, CalibrationStd* camera) {
  // a camera part estimated against a LiDAR part held: the camera against the LiDAR-registered body
  auto against = [](bool camera_estimated, bool lidar_estimated, double cs, double ls) {
    return camera_estimated ? (lidar_estimated ? cs : std::hypot(cs, ls)) : 0.0;
  };
  lidar->rotation = e.lidar_rotation ? l.rotation : 0.0;
  lidar->translation = e.lidar_translation ? l.translation : 0.0;
  lidar->time = e.lidar_time ? l.time : 0.0;
  camera->rotation = against(e.camera_rotation, e.lidar_rotation, c.rotation, l.rotation);
  camera->translation = against(e.camera_translation, e.lidar_translation, c.translation, l.translation);
  camera->time = against(e.camera_time, e.lidar_time, c.time, l.time);
}

FilterState LioEstimator::initialState(const ImuInitResult& r) const {
  FilterState x = r.state;
  x.lidar = has_kept_calibration_ ? kept_calibration_.lidar : SensorCalibration::fromPose(options_.extrinsics.T_I_L);
  x.camera = has_kept_calibration_ ? kept_calibration_.camera : SensorCalibration::fromPose(options_.camera_T_I_C);
  return x;
}

StateCovariance LioEstimator::initialCovariance(const ImuInitResult& r) const {
  constexpr int n = FilterState::kNavDim, c = FilterState::kDim - FilterState::kNavDim;
  StateCovariance P = StateCovariance::Zero();
  P.topLeftCorner<n, n>() = r.covariance;
  if (has_kept_calibration_) {
    P.bottomRightCorner<c, c>() = kept_calibration_cov_.bottomRightCorner<c, c>();
  } else {
    CalibrationStd lidar, camera;
    calibrationPrior(options_.lidar_calibration_std, options_.camera_calibration_std, options_.calibration, &lidar,
                     &camera);
    setCalibrationPrior(FilterState::kLidar, lidar, &P);
    setCalibrationPrior(FilterState::kCamera, camera, &P);
  }
  return P;
}

void LioEstimator::softReset(const ImuSample& s, double gap_s, std::string* note) {
  // Nothing is known about the motion over the gap: keep pose and biases, widen the pose by what
  // the body may have done meanwhile, forget the velocity, and restart at s.
  const double skipped = std::max(0.0, static_cast<double>(s.utime - prop_.utime()) * 1e-6);
  FilterState x = prop_.state();
  // the velocity the LiDAR saw between the last two registered sweeps, if recent
  if (has_prev_post_ && prop_.utime() - prev_post_utime_ > 0 && prop_.utime() - prev_post_utime_ < 500'000)
    x.vel = (x.pos - prev_post_pos_) / (static_cast<double>(prop_.utime() - prev_post_utime_) * 1e-6);
  StateCovariance P = prop_.covariance();
  P.middleRows<3>(FilterState::kVel).setZero();
  P.middleCols<3>(FilterState::kVel).setZero();
  const double v2 = options_.init.moving_vel_std * options_.init.moving_vel_std;
  P.block<3, 3>(FilterState::kVel, FilterState::kVel) = Mat3::Identity() * v2;
  P.block<3, 3>(FilterState::kPos, FilterState::kPos) += Mat3::Identity() * v2 * skipped * skipped;
  const double rot_std = std::min(M_PI / 2, options_.gap_rate_std * skipped);
  P.block<3, 3>(FilterState::kRot, FilterState::kRot) += Mat3::Identity() * rot_std * rot_std;
  prop_.reset(x, P, s);
  clone_.valid = false;  // the velocity starts again: no increment from the last keyframe
  appendNote(note, "IMU gap of " + formatSignificant(gap_s) + " s: velocity re-initialised");
}

void LioEstimator::widenForGap(double gap_s) {
  // a bridged gap: the interpolated IMU says little about the motion, so widen the pose and the
  // velocity by what the body may have done meanwhile
  StateCovariance P = prop_.covariance();
  const double v = options_.init.moving_vel_std;
  const double rot_std = std::min(M_PI / 2, options_.gap_rate_std * gap_s);
  P.block<3, 3>(FilterState::kPos, FilterState::kPos) += Mat3::Identity() * v * v * gap_s * gap_s;
  P.block<3, 3>(FilterState::kRot, FilterState::kRot) += Mat3::Identity() * rot_std * rot_std;
  P.block<3, 3>(FilterState::kVel, FilterState::kVel) += Mat3::Identity() * v * v * std::min(1.0, gap_s);
  prop_.setState(prop_.state(), P);
}

void LioEstimator::continueNumbering(int32_t epoch, int64_t next_keyframe_id) {
  frame_ = OdometryFrame{};
  frame_.epoch = epoch;
  next_keyframe_id_ = next_keyframe_id;
}

void LioEstimator::noteBridgedGap(const FilterState& before) {
  const FilterState& after = prop_.state();
  gap_undo_rot_ = gap_undo_rot_ * (before.rot * after.rot.transpose());
  gap_undo_pos_ += before.pos - after.pos;
  gap_undo_vel_ += before.vel - after.vel;
  gap_bridged_ = true;
}

void LioEstimator::stepTo(const ImuSample& s, double* worst_gap, std::string* note) {
  if (s.utime <= prop_.utime()) return;
  const double gap = static_cast<double>(s.utime - prop_.utime()) * 1e-6;
  if (gap > options_.reset_imu_gap_s) {
    softReset(s, gap, note);
    return;
  }
  const FilterState before = prop_.state();
  prop_.addSample(s);
  if (gap > options_.max_imu_gap_s) {
    noteBridgedGap(before);
    widenForGap(gap);
  }
  *worst_gap = std::max(*worst_gap, gap);
}

void LioEstimator::drainBacklog(int64_t newest) {
  const int64_t backlog = toUtime(options_.max_imu_backlog_s);
  double worst_gap = 0.0;
  while (!imu_.empty() && imu_.front().utime < newest - backlog / 2) {
    const ImuSample s = imu_.front();
    // a sweep may still come for an IMU gap that ended less than a backlog ago: leave it to addScan
    if (static_cast<double>(s.utime - prop_.utime()) * 1e-6 > options_.reset_imu_gap_s && newest - s.utime < backlog)
      break;
    imu_.pop_front();
    stepTo(s, &worst_gap, nullptr);
  }
  prop_.dropSegmentsBefore(prop_.utime() - toUtime(kMaxSweepDurationS));
}

bool LioEstimator::propagateThrough(int64_t t_end, std::string* note) {
  const double max_gap = options_.max_imu_gap_s, reset_gap = options_.reset_imu_gap_s;
  double worst_gap = 0.0;
  while (!imu_.empty() && imu_.front().utime <= t_end) {
    const ImuSample s = imu_.front();
    imu_.pop_front();
    stepTo(s, &worst_gap, note);
  }
  if (prop_.utime() < t_end) {
    const bool has_next = !imu_.empty();
    const ImuSample next = has_next ? imu_.front() : prop_.lastSample();
    const double gap = static_cast<double>((has_next ? next.utime : t_end) - prop_.utime()) * 1e-6;
    const double step = static_cast<double>(t_end - prop_.utime()) * 1e-6;
    if (!has_next)
      appendNote(note, "IMU data ends " + formatSignificant(gap) + " s before the sweep end: last sample held");
    if (gap > reset_gap) {
      ImuSample at = next;
      at.utime = t_end;
      softReset(at, gap, note);
    } else {
      const FilterState before = prop_.state();
      prop_.propagateTo(t_end, next);
      if (gap > max_gap) {
        noteBridgedGap(before);
        widenForGap(step);
      }
      worst_gap = std::max(worst_gap, gap);
    }
  }
  if (worst_gap > max_gap) appendNote(note, "IMU gap of " + formatSignificant(worst_gap) + " s bridged");
  return prop_.state().rot.allFinite() && prop_.state().pos.allFinite() && prop_.state().vel.allFinite() &&
         prop_.covariance().allFinite();
}

bool LioEstimator::wheelSpeedAt(int64_t utime, double* speed, double* scale_variance) const {
  for (size_t i = 1; i < wheel_.size(); ++i) {
    const WheelSample& a = wheel_[i - 1];
    const WheelSample& b = wheel_[i];
    if (a.utime <= utime && utime <= b.utime) {
      if (static_cast<double>(b.utime - a.utime) * 1e-6 > options_.wheel.max_sample_gap_s) return false;
      const double alpha =
          b.utime > a.utime ? static_cast<double>(utime - a.utime) / static_cast<double>(b.utime - a.utime) : 0.0;
      // scales of exactly 1 (calibration off) leave the speeds bit for bit as they came
      const WheelSample ca = wheel_scale_.correct(a), cb = wheel_scale_.correct(b);
      *speed = 0.5 * ((1.0 - alpha) * (ca.left_speed + ca.right_speed) + alpha * (cb.left_speed + cb.right_speed));
      const WheelSample raw{utime, (1.0 - alpha) * a.left_speed + alpha * b.left_speed,
                            (1.0 - alpha) * a.right_speed + alpha * b.right_speed};
      *scale_variance = options_.wheel_scale.enabled ? wheel_scale_.meanSpeedVariance(raw) : 0.0;
      return true;
    }
  }
  return false;
}

void LioEstimator::learnWheelScales(const ScanResult& res, const FilterState& x, const WheelTravel* travel) {
  // a degenerate registration leaves some direction to the IMU and the wheels themselves: the
  // scales would learn from their own speeds
  const bool anchor = res.status == ScanResult::Status::kTracked && !res.degeneracy.degenerate;
  if (anchor && travel) {
    WheelTravel t = *travel;
    t.duration_s = static_cast<double>(res.utime - scale_anchor_utime_) * 1e-6;
    t.predicted = predictedWheelTravel(scale_anchor_pose_, x.pose(), options_.wheel.T_I_B, options_.wheel.track_width,
                                       &t.forward_distance);
    wheel_scale_.update(t, res.utime);
  }
  has_scale_anchor_ = anchor;
  scale_anchor_pose_ = x.pose();
  scale_anchor_utime_ = res.utime;
}

size_t LioEstimator::insertIntoMap(const std::vector<Vec3>& body, const FilterState& x) {
  std::vector<Vec3> world(body.size());
  for (size_t i = 0; i < body.size(); ++i) world[i] = x.rot * body[i] + x.pos;
  // the beams leave the LiDAR where it is at the sweep end (the frame the sweep is undistorted to)
  const Vec3 lidar = x.rot * x.lidar.pos + x.pos;
  const size_t removed = map_.removeSeenThrough(lidar, world, options_.seen_through, search_threads_.get());
  map_.insert(world, lidar);
  return removed;
}

void LioEstimator::pruneMap(const Vec3& position) {
  if ((position - last_prune_position_).norm() < options_.map_prune_distance) return;
  map_.removeFarFrom(position, options_.map_radius);
  planes_.removeFarFrom(position, options_.map_radius);
  last_prune_position_ = position;
}

bool LioEstimator::refusesSweep(int64_t t_end, ScanResult* res) const {
  if (!initialized_) {
    res->status = ScanResult::Status::kInitializing;
    res->message = "waiting for the IMU initialisation";
    return true;
  }
  if (!acceptsSweepEnding(t_end) || (map_.empty() && t_end <= prop_.utime())) {
    // before the first output this is a sweep recorded during the IMU initialisation window
    res->status = map_.empty() ? ScanResult::Status::kInitializing : ScanResult::Status::kRejected;
    res->message = map_.empty() ? "sweep ends before the IMU initialisation" : "sweep ends before the filter time";
    return true;
  }
  return false;
}

ScanResult LioEstimator::addScan(const LidarScan& scan, const SweepTiming& timing) {
  ScanResult res;
  std::string* note = &res.message;
  const int64_t t_end = timing.end_utime, t_first = timing.start_utime;
  if (refusesSweep(t_end, &res)) return res;
  last_sweep_end_utime_ = t_end;

  // 1. propagation to the sweep end (eqs. 5-6)
  if (!propagateThrough(t_end, note)) {
    appendNote(note, "propagation produced a non-finite state: re-initialising");
    reset();
    res.status = ScanResult::Status::kRejected;
    return res;
  }
  FilterState x = prop_.state();
  StateCovariance P = prop_.covariance();

  // 2. valid points, undistorted into the body frame at the end
  const std::vector<size_t> valid = validPoints(scan, timing.end_offset_s, note);
  res.num_points = static_cast<int>(valid.size());
  std::vector<Vec3> body = undistortToSweepEnd(scan, valid, x, t_first, t_end);
  const SensorCalibration undistorted_with = x.lidar;  // the wheel update below may move it

  // 3. registration subset: stride, then voxel downsampling
  std::vector<Vec3> reg = registrationSubset(body, options_.point_stride, options_.scan_voxel_size);
  res.num_registered = static_cast<int>(reg.size());

  // 4. wheel velocity (before the LiDAR update), and what the wheels travelled since the last
  // wheel-scale anchor (learnt from after the LiDAR update)
  WheelTravel travel;
  const bool has_travel = options_.wheel.enabled && wheelVelocityStage(t_end, &x, &P, &travel, note);

  // 5. LiDAR update or map seeding
  reseedAfterOutage(t_end, &x, &P, note);
  const Vec3 body_rate = prop_.angularVelocity(prop_.lastSample().gyro, x);
  res.status = lidarStage(reg, valid.size(), undistorted_with, body_rate, &x, &P, &res);
  toBodyAtSweepEnd(undistorted_with, x, body_rate, &body, &reg);
  noteRegistration(res.status, x, t_end);
  prop_.applyUpdate(x, P);
  res.utime = t_end;
  if (options_.wheel.enabled && options_.wheel_scale.enabled) learnWheelScales(res, x, has_travel ? &travel : nullptr);

  // 6. the sweep in the world (an output, and what the voxel planes take), map insertion and the
  // local window
  worldPoints(body, valid, x, &res);
  if (res.status != ScanResult::Status::kPredicted) addToMap(reg, x, res.world_points, &res);

  // 7. outputs
  res.sweep_start_utime = t_first;
  res.state = x;
  res.covariance = P;
  res.angular_velocity = prop_.angularVelocity(prop_.lastSample().gyro, x);
  if (res.status != ScanResult::Status::kPredicted && keyframe_selector_.check(x.pose())) {
    res.is_keyframe = true;
    res.keyframe = makeKeyframe(scan, valid, body, x, P, t_end);
  }
  return res;
}

void LioEstimator::addToMap(const std::vector<Vec3>& reg, const FilterState& x, const std::vector<Vec3>& world,
                            ScanResult* res) {
  res->map_points_seen_through = insertIntoMap(reg, x);
  if (options_.planes.enabled) planes_.add(world, x.rot * x.lidar.pos + x.pos);
  last_registered_body_ = reg;
  pruneMap(x.pos);
}

std::vector<size_t> LioEstimator::validPoints(const LidarScan& scan, double end_offset, std::string* note) const {
  std::vector<size_t> valid;
  const size_t n = std::min(scan.points.size(), scan.time_offset.size());
  const double min_r2 = options_.min_range * options_.min_range, max_r2 = options_.max_range * options_.max_range;
  const bool has_intensity = scan.intensity.size() == scan.points.size();
  for (size_t j = 0; j < n; ++j) {
    const Vec3& p = scan.points[j];
    const float t = scan.time_offset[j];
    if (!p.allFinite() || !std::isfinite(t) || t < 0.0f || t > end_offset) continue;
    if (has_intensity && !std::isfinite(scan.intensity[j])) continue;  // a corrupted point
    const double r2 = p.squaredNorm();
    if (r2 < min_r2 || r2 > max_r2) continue;
    valid.push_back(j);
  }
  if (scan.points.size() != scan.time_offset.size()) appendNote(note, "points and time offsets differ in number");
  return valid;
}

std::vector<Vec3> LioEstimator::undistortToSweepEnd(const LidarScan& scan, const std::vector<size_t>& valid,
                                                    const FilterState& at_end, int64_t t_first, int64_t t_end) {
  const Pose3 T_I_L = at_end.lidar.pose();
  std::vector<Vec3> body;
  if (!prop_.segments().empty()) {
    const Undistorter und(prop_.segments(), at_end.rot, at_end.pos, t_end, T_I_L);
    // each point at its stamp plus the LiDAR's time shift in use (the rate changes within a sweep)
    und.undistort(scan, t_first, at_end.lidar.dt, valid, &body);
  } else {
    for (size_t j : valid) body.push_back(T_I_L * scan.points[j]);
  }
  prop_.clearSegments();
  return body;
}

void LioEstimator::toBodyAtSweepEnd(const SensorCalibration& undistorted_with, const FilterState& x,
                                    const Vec3& body_rate, std::vector<Vec3>* body, std::vector<Vec3>* reg) {
  // body and reg hold the points through the calibration of the undistortion, as if taken at the
  // filter's time; the sweep was seen through x's extrinsic at the state's time plus what the time
  // shift moved beyond the undistortion's (ScanToMap): A = T_W_I^-1 T_W_I(end) T_I_L(x) T_I_L(undistortion)^-1
  const bool same =
      x.lidar.dt == undistorted_with.dt && x.lidar.rot == undistorted_with.rot && x.lidar.pos == undistorted_with.pos;
  if (same) return;
  const Pose3 A = x.pose().inverse() * sweepEndPose(x, body_rate, undistorted_with.dt) * x.lidar.pose() *
                  undistorted_with.pose().inverse();
  for (Vec3& p : *body) p = A * p;
  for (Vec3& p : *reg) p = A * p;
}

bool LioEstimator::wheelVelocityStage(int64_t t_end, FilterState* x, StateCovariance* P, WheelTravel* travel,
                                      std::string* note) {
  bool has_travel = false;
  if (options_.wheel_scale.enabled && has_scale_anchor_)
    has_travel = integrateWheelSpeeds(wheel_, scale_anchor_utime_, t_end, options_.wheel.max_sample_gap_s,
                                      &travel->measured, &travel->measured_noise_gain);
  double speed = 0.0, scale_variance = 0.0;
  if (wheelSpeedAt(t_end, &speed, &scale_variance)) {
    const WheelUpdateResult w = wheelVelocityUpdate(x, P, nominalGyro(*x), speed, options_.wheel, scale_variance);
    ++(w.applied ? wheel_counts_.accepted : wheel_counts_.rejected);
    if (!w.applied)
      appendNote(note, "wheel speed rejected (chi2 " + formatSignificant(w.chi2) + "; filter minus wheels forward " +
                           formatSignificant(w.innovation.x()) + ", lateral " + formatSignificant(w.innovation.y()) +
                           ", vertical " + formatSignificant(w.innovation.z()) + " m/s)");
  } else {
    ++wheel_counts_.no_reading;
    appendNote(note, "no wheel reading around the sweep end");
  }
  while (wheel_.size() > 2 && wheel_[1].utime <= t_end) wheel_.pop_front();
  return has_travel;
}

void LioEstimator::reseedAfterOutage(int64_t t_end, FilterState* x, StateCovariance* P, std::string* note) {
  // After reseed_after_s without a registration (a LiDAR outage, lost track) the map no longer
  // fits the predicted pose: a new one is seeded there, so the trajectory goes on from the
  // prediction instead of restarting at the origin.
  if (map_.empty() || !has_registered_) return;
  const double lost_s = static_cast<double>(t_end - last_registered_utime_) * 1e-6;
  if (lost_s <= options_.reseed_after_s) return;
  map_.clear();
  planes_.clear();
  // the IMU-only velocity of a long outage is worthless: keep it only after a short one
  if (lost_s > 3.0 * options_.reseed_after_s) x->vel.setZero();
  const double v2 = options_.init.moving_vel_std * options_.init.moving_vel_std;
  P->middleRows<3>(FilterState::kVel).setZero();
  P->middleCols<3>(FilterState::kVel).setZero();
  P->block<3, 3>(FilterState::kVel, FilterState::kVel) = Mat3::Identity() * v2;
  appendNote(note, "no registration for " + formatSignificant(lost_s) + " s: map re-seeded at the predicted pose");
}

ScanResult::Status LioEstimator::lidarStage(const std::vector<Vec3>& reg, size_t num_valid,
                                            const SensorCalibration& undistorted_with, const Vec3& body_rate,
                                            FilterState* x, StateCovariance* P, ScanResult* res) {
  std::string* note = &res->message;
  ScanResult::Status status;
  if (map_.empty()) {
    if (static_cast<int>(num_valid) < options_.min_points) {
      status = ScanResult::Status::kPredicted;
      appendNote(note, "too few valid points to seed the map (" + std::to_string(num_valid) + ")");
    } else {
      status = ScanResult::Status::kMapInitialized;
    }
  } else if (static_cast<int>(num_valid) < options_.min_points) {
    status = ScanResult::Status::kPredicted;
    appendNote(note, "too few valid points (" + std::to_string(num_valid) + "): prediction only");
  } else {
    status = registerSweep(reg, undistorted_with, body_rate, x, P, res);
  }
  gap_bridged_ = false;
  gap_undo_rot_.setIdentity();
  gap_undo_pos_.setZero();
  gap_undo_vel_.setZero();
  return status;
}

ScanResult::Status LioEstimator::registerSweep(const std::vector<Vec3>& reg, const SensorCalibration& undistorted_with,
                                               const Vec3& body_rate, FilterState* x, StateCovariance* P,
                                               ScanResult* res) {
  std::string* note = &res->message;
  ScanToMap s2m(map_, planesForRegistration(), reg, options_.matching, search_threads_.get(), undistorted_with,
                body_rate);
  FilterState post;
  StateCovariance P_post;
  EsikfResult er = iteratedUpdate(
      *x, *P, [&](const FilterState& xi, int it, MeasurementInformation* info) { return s2m.evaluate(xi, it, info); },
      options_.esikf, &post, &P_post);
  const ScanToMap* fitted = &s2m;
  std::optional<ScanToMap> s2m_still;
  if (gap_bridged_) {
    // After a bridged IMU gap the prediction assumed the gap's time really passed. If it did not
    // (every sensor's clock stepped ahead), the body stood still meanwhile: try that too and keep
    // the registration that finds more of the map.
    FilterState still = *x;
    still.rot = gap_undo_rot_ * x->rot;
    still.pos = x->pos + gap_undo_pos_;
    still.vel = x->vel + gap_undo_vel_;
    s2m_still.emplace(map_, planesForRegistration(), reg, options_.matching, search_threads_.get(), undistorted_with,
                      body_rate);
    FilterState post_still;
    StateCovariance P_still;
    const EsikfResult er_still = iteratedUpdate(
        still, *P,
        [&](const FilterState& xi, int it, MeasurementInformation* info) { return s2m_still->evaluate(xi, it, info); },
        options_.esikf, &post_still, &P_still);
    if (er_still.valid && er_still.info.count > (er.valid ? er.info.count : 0) * 11 / 10) {
      appendNote(note, "after the IMU gap the sweep fits the map better as if no time had passed (" +
                           std::to_string(er_still.info.count) + " against " + std::to_string(er.info.count) +
                           " matches): the clock stepped");
      *x = still;
      fitted = &*s2m_still;
      er = er_still;
      post = post_still;
      P_post = P_still;
    }
  }
  res->num_residuals = er.info.count;
  res->iterations = er.iterations;
  res->converged = er.converged;
  res->degeneracy = fitted->degeneracy();
  res->min_information_eigenvalue = fitted->minInformationEigenvalue();
  const bool enough = er.valid && er.info.count >= options_.min_residuals;
  const bool sane = enough && post.rot.allFinite() && post.pos.allFinite() && P_post.allFinite() &&
                    (post.pos - x->pos).norm() <= options_.max_position_jump;
  if (!sane) {
    res->degeneracy.degenerate = true;
    appendNote(note, enough ? "update rejected (diverged)"
                            : "too few point-to-plane matches (" + std::to_string(er.info.count) + ")");
    return ScanResult::Status::kPredicted;
  }
  *x = post;
  *P = P_post;
  return ScanResult::Status::kTracked;
}

void LioEstimator::noteRegistration(ScanResult::Status status, const FilterState& x, int64_t t_end) {
  if (status == ScanResult::Status::kTracked || status == ScanResult::Status::kMapInitialized) {
    last_registered_utime_ = t_end;
    has_registered_ = true;
  }
  if (status == ScanResult::Status::kTracked) {
    // remember the previous registered position (velocity after IMU gaps)
    if (has_last_post_) {
      prev_post_pos_ = last_post_pos_;
      prev_post_utime_ = last_post_utime_;
      has_prev_post_ = true;
    }
    last_post_pos_ = x.pos;
    last_post_utime_ = t_end;
    has_last_post_ = true;
  }
}

HeldCalibration LioEstimator::heldCalibration(const FilterState& x) const {
  HeldCalibration held;
  held.T_I_L = x.lidar.pose();
  held.lidar_rotation_std = options_.calibration.lidar_rotation ? 0.0 : options_.lidar_calibration_std.rotation;
  held.lidar_translation_std =
      options_.calibration.lidar_translation ? 0.0 : options_.lidar_calibration_std.translation;
  if (!prop_.modelsIntrinsics()) {  // modelled, they are in the filter's covariance
    held.gyro_scale_std = options_.imu_noise.gyro_scale_std;
    held.gyro_misalignment_std = options_.imu_noise.gyro_misalignment_std;
  }
  return held;
}

Keyframe LioEstimator::makeKeyframe(const LidarScan& scan, const std::vector<size_t>& valid,
                                    const std::vector<Vec3>& body, const FilterState& x, const StateCovariance& P,
                                    int64_t t_end) {
  Keyframe kf;
  kf.id = next_keyframe_id_++;
  kf.utime = t_end;
  kf.pose = x.pose();
  kf.pose_covariance = P.topLeftCorner<6, 6>();
  if (clone_.valid) {
    kf.relative_to_id = clone_.keyframe_id;
    kf.relative_covariance = relativePoseCovariance(clone_.pose, kf.pose, clone_.covariance, kf.pose_covariance,
                                                    prop_.cloneCross().topRows<6>());
    kf.relative_covariance_held_calibration =
        heldCalibrationCovariance(clone_.pose.inverse() * kf.pose, heldCalibration(x));
    kf.relative_covariance += kf.relative_covariance_held_calibration;
  }
  // the next keyframe's increment starts here: Cov(δx, δpose) is P's pose columns
  clone_ = KeyframeClone{true, kf.id, kf.pose, kf.pose_covariance};
  prop_.clonePose();
  const bool has_intensity = scan.intensity.size() == scan.points.size();
  for (size_t i : firstPointPerVoxel(body, options_.keyframe.cloud_voxel)) {
    kf.cloud.push_back(body[i]);
    kf.intensity.push_back(has_intensity ? scan.intensity[valid[i]] : 0.0f);
  }
  keyframes_.push_back(kf);
  while (keyframes_.size() > options_.max_stored_keyframes) keyframes_.pop_front();
  return kf;
}

bool LioEstimator::propagateTo(int64_t utime, std::string* why) {
  if (!initialized_) {
    if (why) *why = "not initialised";
    return false;
  }
  if (utime < prop_.utime()) {
    if (why) *why = "time before the filter time";
    return false;
  }
  std::string note;
  const bool ok = propagateThrough(utime, &note);
  if (why) *why = note;
  return ok;
}

bool LioEstimator::adoptPosterior(int64_t utime, const FilterState& x, const StateCovariance& P, std::string* why) {
  auto fail = [&](const char* w) {
    if (why) *why = w;
    return false;
  };
  if (!initialized_) return fail("not initialised");
  if (utime != prop_.utime()) return fail("posterior time differs from the filter time");
  if (!x.rot.allFinite() || !x.pos.allFinite() || !x.vel.allFinite() || !x.gyro_bias.allFinite() ||
      !x.accel_bias.allFinite() || !x.gravity.allFinite() || !x.lidar.rot.allFinite() || !x.lidar.pos.allFinite() ||
      !std::isfinite(x.lidar.dt) || !x.camera.rot.allFinite() || !x.camera.pos.allFinite() ||
      !std::isfinite(x.camera.dt) || !P.allFinite())
    return fail("non-finite posterior");
  for (const Mat3* R : {&x.rot, &x.lidar.rot, &x.camera.rot})
    if ((R->transpose() * *R - Mat3::Identity()).norm() > 1e-6) return fail("posterior rotation not orthonormal");
  const StateCovariance Ps = 0.5 * (P + P.transpose());
  if (!isUsableCovariance(Ps)) return fail("posterior covariance not positive definite");
  // a calibration the filter holds fixed stays fixed: a posterior may not start estimating it
  for (int i = FilterState::kNavDim; i < FilterState::kDim; ++i)
    if ((prop_.covariance()(i, i) == 0.0) != (Ps(i, i) == 0.0))
      return fail("posterior estimates a calibration the filter holds fixed");
  // the sweep in progress is undistorted along the recorded segments: move them with the state
  const FilterState& prior = prop_.state();
  Pose3 T = Pose3::Identity();
  T.linear() = x.rot * prior.rot.transpose();
  T.translation() = x.pos - T.linear() * prior.pos;
  prop_.transformSegments(T);
  prop_.applyUpdate(x, Ps);
  return true;
}

void LioEstimator::applyLoopCorrection(const LoopCorrection& correction, const std::vector<KeyframePose>& corrected) {
  const Pose3 T = correctionStep(frame_, correction);
  frame_.correction_id = correction.id;
  frame_.T_C_O = correction.T_Ck_O;
  has_scale_anchor_ = false;  // its pose is in the frame before the correction
  const Mat3 Rc = T.linear();
  // keyframes: corrected poses where given, the rigid correction elsewhere
  for (auto& kf : keyframes_) {
    auto it = std::find_if(corrected.begin(), corrected.end(), [&](const KeyframePose& k) { return k.id == kf.id; });
    kf.pose = it != corrected.end() ? it->pose : T * kf.pose;
  }
  if (initialized_) {
    FilterState x = prop_.state();
    x.rot = so3::normalize(Rc * x.rot);
    x.pos = Rc * x.pos + T.translation();
    x.vel = Rc * x.vel;
    x.gravity = Rc * x.gravity;
    StateCovariance Tm = StateCovariance::Identity();  // the calibration is in the body frames: unmoved
    Tm.block<3, 3>(FilterState::kPos, FilterState::kPos) = Rc;
    Tm.block<3, 3>(FilterState::kVel, FilterState::kVel) = Rc;
    Tm.block<3, 3>(FilterState::kGravity, FilterState::kGravity) = Rc;
    // the clone moves with the frame: the relative pose and its covariance do not change
    Mat6 Tc = Mat6::Identity();
    Tc.bottomRightCorner<3, 3>() = Rc;
    prop_.changeFrame(x, Tm, Tc);
    // the sweep in progress is undistorted along the recorded segments: they move with the frame
    prop_.transformSegments(T);
    keyframe_selector_.setReference(x.pose());
    if (clone_.valid) {
      clone_.pose = T * clone_.pose;
      clone_.covariance = Tc * clone_.covariance * Tc.transpose();
    }
  }
  if (options_.map_on_loop_correction == LioOptions::OnLoopCorrection::kMove) {
    map_.transform(T);
    planes_.clear();  // the cells do not follow a rotation of the grid: they fill again
    last_prune_position_ = T * last_prune_position_;
    return;
  }
  // rebuild the local map from the corrected keyframes around the new position
  map_.clear();
  planes_.clear();
  const Vec3 lidar_position = initialized_ ? prop_.state().lidar.pos : options_.extrinsics.T_I_L.translation();
  const Vec3 here = initialized_ ? prop_.state().pos : T.translation();
  for (auto it = keyframes_.rbegin(); it != keyframes_.rend(); ++it) {
    if ((it->pose.translation() - here).norm() > options_.map_radius) continue;
    const Vec3 lidar = it->pose * lidar_position;
    for (const auto& p : it->cloud) {
      const Vec3 w = it->pose * p;
      map_.insert(w, (w - lidar).norm());
    }
  }
  if (initialized_) insertIntoMap(last_registered_body_, prop_.state());
  last_prune_position_ = here;
}

}  // namespace livo::lio
