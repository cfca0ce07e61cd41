#include "livo/vio_feature/sliding_window_estimator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <ceres/ceres.h>

#include "livo/graph_factors.hpp"
#include "livo/inertial_window.hpp"
#include "livo/sample_interval.hpp"
#include "livo/start_state_prior.hpp"
#include "livo/time.hpp"
#include "livo/vio_feature/reprojection_factor.hpp"

namespace livo::vio_feature {

const char* statusName(FrameResult::Status s) {
  switch (s) {
    case FrameResult::Status::kRejected: return "rejected";
    case FrameResult::Status::kInitializing: return "initializing";
    case FrameResult::Status::kInitialized: return "initialized";
    case FrameResult::Status::kTracked: return "tracked";
  }
  return "?";
}

/// One state of the window and the factors that end at it (from the previous state).
struct SlidingWindowEstimator::Frame {
  int64_t utime = 0;  // IMU clock
  double q[4] = {0, 0, 0, 1};
  double p[3] = {0, 0, 0};
  double v[3] = {0, 0, 0};
  double bg[3] = {0, 0, 0};
  double ba[3] = {0, 0, 0};
  bool keyframe = true;
  std::vector<ImuSample> imu_samples;      // from the previous state's time to this one
  std::vector<WheelSample> wheel_samples;  // the same (empty: no wheel factor)
  std::unique_ptr<ceres::CostFunction> imu, bias_walk, wheel;
  std::unique_ptr<ceres::LossFunction> wheel_loss;
  std::vector<std::unique_ptr<ceres::CostFunction>> priors;  // the first state's
  std::vector<std::vector<double*>> prior_blocks;

  Pose3 pose() const { return poseFromBlocks(q, p); }
  void setPose(const Pose3& T) {
    Eigen::Map<Eigen::Quaterniond>{q} = Eigen::Quaterniond(T.linear()).normalized();
    Eigen::Map<Vec3>{p} = T.translation();
  }
  Vec3 gyroBias() const { return Vec3(bg[0], bg[1], bg[2]); }
  Vec3 accelBias() const { return Vec3(ba[0], ba[1], ba[2]); }
  Vec3 velocity() const { return Vec3(v[0], v[1], v[2]); }
  InertialBlocks inertial() { return {q, p, v, bg, ba}; }
};

/// A tracked feature: its inverse depth along the ray of its first observation in the window (the
/// anchor) and its observations, the anchor's first.
struct SlidingWindowEstimator::Feature {
  struct Observation {
    Frame* frame;
    Vec2 xy;
    double depth;                               // measured, 0: none
    std::unique_ptr<ceres::CostFunction> cost;  // reprojection from the anchor (null for the anchor)
  };
  std::vector<Observation> obs;
  double rho[1] = {0.0};
  bool has_rho = false;
  bool in_graph = false;  // was in the last optimisation (its factors then go into a marginal prior)
  std::unique_ptr<ceres::CostFunction> depth_prior;  // the anchor's measured depth

  Frame* anchor() const { return obs.front().frame; }
};

namespace {

constexpr double kStillWheelSpeed = 0.02;  // m/s: a wheel turning slower than this is at rest

double depthSigma(const SlidingWindowOptions& o, double d) { return o.depth_sigma_base + o.depth_sigma_relative * d; }

bool validDepth(const SlidingWindowOptions& o, double d) {
  return std::isfinite(d) && d >= o.min_depth && d <= o.max_depth;
}

template <class Sample>
bool pushSample(std::deque<Sample>* buf, const Sample& s, bool finite, const char* what, std::string* why) {
  if (!finite) {
    if (why) *why = std::string("non-finite ") + what;
    return false;
  }
  if (!buf->empty() && s.utime <= buf->back().utime) {
    if (why) *why = std::string(what) + " not later than the previous one";
    return false;
  }
  buf->push_back(s);
  return true;
}

}  // namespace

SlidingWindowEstimator::SlidingWindowEstimator(const SlidingWindowOptions& options)
    : options_(options),
      gravity_W_(0.0, 0.0, -options.gravity),
      reprojection_loss_(std::make_unique<ceres::CauchyLoss>(options.reprojection_cauchy)) {}

SlidingWindowEstimator::~SlidingWindowEstimator() = default;

bool SlidingWindowEstimator::addImu(const ImuSample& s, std::string* why) {
  if (!pushSample(&imu_, s, s.gyro.allFinite() && s.accel.allFinite(), "IMU sample", why)) return false;
  // keep what the oldest state and the initialisation windows may still need
  const int64_t keep = window_.empty()
                           ? s.utime - toUtime(std::max(options_.init.window_s, options_.moving_init_window_s) + 1.0)
                           : window_.back()->utime - toUtime(1.0);
  while (imu_.size() > 2 && imu_[1].utime <= keep) imu_.pop_front();
  return true;
}

bool SlidingWindowEstimator::addWheel(const WheelSample& s, std::string* why) {
  if (!pushSample(&wheel_, s, std::isfinite(s.left_speed) && std::isfinite(s.right_speed), "wheel reading", why))
    return false;
  const int64_t keep =
      window_.empty() ? s.utime - toUtime(options_.moving_init_window_s + 1.0) : window_.back()->utime - toUtime(1.0);
  while (wheel_.size() > 2 && wheel_[1].utime <= keep) wheel_.pop_front();
  return true;
}

void SlidingWindowEstimator::reset() {
  // wheel_scale_ and wheel_mounting_ stay: the vehicle has not changed, and the next window's priors
  // start from them
  features_.clear();
  rejected_.clear();
  recent_.clear();
  prior_factor_.reset();
  prior_.reset();
  window_.clear();
}

FrameResult SlidingWindowEstimator::addFrame(const FrameFeatures& in) {
  FrameResult res;
  const int64_t t = in.utime + toUtime(options_.camera_time_offset_s);
  if (imu_.empty() || imu_.back().utime < t) {
    res.note = "no IMU up to the image's time";
    return res;
  }
  if (!window_.empty() && t <= window_.back()->utime) {
    res.note = "image not later than the previous one";
    return res;
  }
  if (window_.empty()) {
    if (!initialize(t, in, &res)) return res;
    window_.back()->keyframe = true;
    addObservations(*window_.back(), in);
    res.status = FrameResult::Status::kInitialized;
    res.state = stateOf(*window_.back());
    res.wheel_scale = wheelScale();
    res.wheel_mounting = wheelMounting();
    return res;
  }

  auto f = std::make_unique<Frame>();
  f->utime = t;
  Frame& prev = *window_.back();
  // a keyframe at least every max_keyframe_interval_s, so that merged intervals stay bounded
  const Frame& last_key = **std::find_if(window_.rbegin(), window_.rend(), [](const auto& w) { return w->keyframe; });
  f->keyframe = in.keyframe || toSeconds(t - last_key.utime) >= options_.max_keyframe_interval_s;
  std::string why;
  if (!connect(prev, *f, true, &why)) {
    reset();
    res.note = why + ": restarting";
    return res;
  }
  window_.push_back(std::move(f));
  Frame& cur = *window_.back();
  addObservations(cur, in);
  triangulate();
  std::vector<Feature*> graph = graphFeatures();
  optimize(graph);
  res.outliers = rejectOutliers();
  if (res.outliers > 0) graph = graphFeatures();
  for (Feature* ft : graph) res.features_with_depth += ft->depth_prior != nullptr;
  res.features_in_graph = static_cast<int>(graph.size());
  res.status = FrameResult::Status::kTracked;
  res.state = stateOf(cur);
  res.state.pose_covariance = newestPoseCovariance(graph);
  res.wheel_scale = wheelScale();
  res.wheel_mounting = wheelMounting();

  // The previous newest state stays if it is a keyframe (the oldest then leaves), else it goes.
  if (static_cast<int>(window_.size()) > options_.window_frames) {
    if (window_[window_.size() - 2]->keyframe)
      marginalizeOldest();
    else
      dropSecondNewest();
  }
  return res;
}

bool SlidingWindowEstimator::cameraStill(int64_t t, const FrameFeatures& frame) {
  std::map<uint64_t, Vec2> now;
  for (const FeatureMeasurement& m : frame.features) now[m.id] = m.xy;
  recent_.emplace_back(t, std::move(now));
  const int64_t span = toUtime(options_.init.window_s);
  while (recent_.size() > 2 && recent_[1].first <= t - span) recent_.pop_front();
  if (recent_.size() < 2 || recent_.front().first > t - span) return false;
  std::vector<double> moved;
  const auto& then = recent_.front().second;
  for (const auto& [id, xy] : recent_.back().second) {
    const auto it = then.find(id);
    if (it != then.end()) moved.push_back((xy - it->second).norm() * options_.focal);
  }
  if (moved.size() < 10) return false;
  std::nth_element(moved.begin(), moved.begin() + static_cast<long>(moved.size() / 2), moved.end());
  return moved[moved.size() / 2] < options_.still_parallax_px;
}

bool SlidingWindowEstimator::initialize(int64_t t, const FrameFeatures& frame, FrameResult* res) {
  res->status = FrameResult::Status::kInitializing;
  const bool camera_still = cameraStill(t, frame);
  // A car cruising on a smooth road can look still to the IMU: where the wheels turn, it is not.
  bool wheels_turn = false;
  if (options_.use_wheel)
    for (const WheelSample& w : wheel_)
      if (w.utime <= t && w.utime >= t - toUtime(options_.init.window_s))
        wheels_turn |= std::abs(w.left_speed) + std::abs(w.right_speed) > 2.0 * kStillWheelSpeed;
  if (wheels_turn) return initializeMoving(t, res);
  if (initializeAtRest(t, camera_still, res)) return true;
  if (options_.use_wheel && initializeMoving(t, res)) return true;
  if (res->note.empty())
    res->note = options_.use_wheel ? "waiting for rest or for the wheels" : "waiting for the IMU at rest";
  return false;
}

bool SlidingWindowEstimator::initializeAtRest(int64_t t, bool camera_still, FrameResult* res) {
  const std::vector<ImuSample> window = imuStartWindow(imu_, t, options_.init.window_s);
  if (!startWindowFilled(window, options_.init.window_s)) {
    res->note = kWaitingForImuStartWindow;
    return false;
  }
  ImuInitOptions init = options_.init;
  init.gravity = options_.gravity;
  init.mode = ImuInitOptions::Mode::kStatic;
  if (camera_still) init.max_gyro_std = init.max_accel_std = std::numeric_limits<double>::infinity();
  const ImuInitResult r = initializeImu(window, init);
  if (!r.ok) return false;
  // the mean's own uncertainty where the IMU shakes: the samples' spread over their number
  Vec3 mean = Vec3::Zero(), var = Vec3::Zero();
  for (const ImuSample& s : window) mean += s.gyro;
  mean /= static_cast<double>(window.size());
  for (const ImuSample& s : window) var += (s.gyro - mean).cwiseAbs2();
  const double gyro_mean_std = std::sqrt(var.maxCoeff() / static_cast<double>(window.size() * window.size()));
  StartStateSigmas sigma = restStartSigmas(init);
  sigma.gyro_bias += gyro_mean_std;
  startWindow(t, r.state.rot, Vec3::Zero(), r.state.gyro_bias, r.state.accel_bias, sigma);
  res->static_start = true;
  res->note = "initialised at rest";
  if (camera_still && !isStill(window, options_.init))
    res->note = "initialised at rest (the images still, the IMU shaking)";
  return true;
}

bool SlidingWindowEstimator::initializeMoving(int64_t t, FrameResult* res) {
  const int64_t t0 = t - toUtime(options_.moving_init_window_s);
  std::vector<ImuSample> imu;
  std::vector<WheelSample> wheel;
  if (imu_.empty() || imu_.front().utime > t0 || !samplesOver(imu_, t0, t, &imu)) return false;
  if (wheel_.empty() || wheel_.front().utime > t0 || !samplesOver(wheel_, t0, t, &wheel)) {
    res->note = "waiting for the wheels over the initialisation window";
    return false;
  }
  // The body-frame velocity from the wheels: the wheel frame B moves forward at the mean speed
  // (through the tyre scales and the mounting as estimated so far: nominal unless an earlier epoch
  // learnt them); v_I = R_IB v_B - w x t_IB.
  const Mat3 R_IB = options_.wheel_rig.T_I_B.linear() * so3::Exp(wheelMounting());
  const Vec3 t_IB = options_.wheel_rig.T_I_B.translation();
  auto bodyVelocity = [&](const WheelSample& w, const Vec3& gyro) {
    const double forward = 0.5 * (wheel_scale_[0] * w.left_speed + wheel_scale_[1] * w.right_speed);
    return Vec3(R_IB * Vec3(forward, 0.0, 0.0) - gyro.cross(t_IB));
  };
  // Integrated over the window with R_k the body's rotation at k in the frame at t0 (from the gyro):
  //   sum R_k f_k dt = [R v]_{t0}^{t} - T g_0   (d(R v)/dt = R (dv/dt + w x v) = R (f + g_k)),
  // so g_0 = ([R v] - sum R_k f_k dt) / T, gravity in the body frame at t0.
  Mat3 R = Mat3::Identity();
  Vec3 sum_f = Vec3::Zero();
  for (size_t k = 0; k + 1 < imu.size(); ++k) {
    const double dt = toSeconds(imu[k + 1].utime - imu[k].utime);
    if (dt <= 0.0) continue;
    const Vec3 w = 0.5 * (imu[k].gyro + imu[k + 1].gyro);
    const Mat3 R_mid = R * so3::Exp(0.5 * dt * w);
    sum_f += R_mid * (0.5 * (imu[k].accel + imu[k + 1].accel)) * dt;
    R = R * so3::Exp(dt * w);
  }
  const double T = toSeconds(t - t0);
  const Vec3 v0 = bodyVelocity(wheel.front(), imu.front().gyro);
  const Vec3 v1 = bodyVelocity(wheel.back(), imu.back().gyro);
  const Vec3 g0 = (R * v1 - v0 - sum_f) / T;
  if (!g0.allFinite() || std::abs(g0.norm() - options_.gravity) > 0.1 * options_.gravity) {
    res->note = "moving initialisation: gravity from the wheels is off (" + std::to_string(g0.norm()) + " m/s^2)";
    return false;
  }
  // W_R_I at t: "up" (-g) onto +z, yaw zero
  const Vec3 up_t = -(R.transpose() * g0).normalized();
  const Mat3 R_W_I = Quat::FromTwoVectors(up_t, Vec3::UnitZ()).toRotationMatrix();
  const Vec3 v_W = R_W_I * v1;
  // With the scales estimated, the velocity's prior carries their uncertainty too: through the
  // first wheel factors a velocity prior at the nominal radii is a prior on the scales (at 10 m/s
  // with the rig's 2 cm/s, sigma 0.11 m/s is 1.1 % of the speed: tighter than wheel_scale_std).
  double vel_std = 3.0 * options_.wheel_noise.speed_std + 0.05;
  if (estimatesWheelScale()) vel_std = std::hypot(vel_std, options_.wheel_scale_std * v_W.norm());
  // likewise the mounting's: its rotation turns the velocity's direction
  if (estimatesWheelMounting()) vel_std = std::hypot(vel_std, options_.wheel_rig.mountingStdRad() * v_W.norm());
  startWindow(
      t, R_W_I, v_W, Vec3::Zero(), Vec3::Zero(),
      {options_.moving_init_rot_std, vel_std, options_.init.moving_gyro_bias_std, options_.init.accel_bias_std});
  res->static_start = false;
  res->note = "initialised in motion from the wheels";
  return true;
}

void SlidingWindowEstimator::startWindow(int64_t t, const Mat3& R, const Vec3& v, const Vec3& bg, const Vec3& ba,
                                         const StartStateSigmas& sigma) {
  auto f = std::make_unique<Frame>();
  f->utime = t;
  f->setPose(se3::fromRotationTranslation(R, Vec3::Zero()));
  Eigen::Map<Vec3>{f->v} = v;
  Eigen::Map<Vec3>{f->bg} = bg;
  Eigen::Map<Vec3>{f->ba} = ba;
  // the gauge (yaw, position) held firmly; roll, pitch, velocity and biases as initialised
  const Mat6 info = startPoseInformation(sigma.rotation, options_.init.yaw_std, options_.init.pos_std);
  f->priors.emplace_back(makePoseFactor(f->pose(), info));
  f->prior_blocks.push_back({f->q, f->p});
  f->priors.emplace_back(makeVectorPriorFactor(v, Vec3::Constant(sigma.velocity)));
  f->prior_blocks.push_back({f->v});
  f->priors.emplace_back(makeVectorPriorFactor(bg, Vec3::Constant(sigma.gyro_bias)));
  f->prior_blocks.push_back({f->bg});
  f->priors.emplace_back(makeVectorPriorFactor(ba, Vec3::Constant(sigma.accel_bias)));
  f->prior_blocks.push_back({f->ba});
  // the tyre scales, once per window (epoch): around what an earlier epoch learnt, [1, 1] at first
  if (estimatesWheelScale()) {
    f->priors.emplace_back(makeWheelScalePrior(wheelScale(), options_.wheel_scale_std));
    f->prior_blocks.push_back({wheel_scale_});
  }
  // the wheel mounting likewise, with the rig's sigma
  if (estimatesWheelMounting()) {
    f->priors.emplace_back(makeWheelMountingPrior(wheelMounting(), options_.wheel_rig.mountingStdRad()));
    f->prior_blocks.push_back({wheel_mounting_});
  }
  window_.push_back(std::move(f));
  recent_.clear();
}

bool SlidingWindowEstimator::connect(Frame& from, Frame& to, bool predict, std::string* why) {
  if (to.imu_samples.empty() && !samplesOver(imu_, from.utime, to.utime, &to.imu_samples)) {
    *why = "no IMU over the interval";
    return false;
  }
  const std::vector<ImuSample>& s = to.imu_samples;
  if (s.front().utime != from.utime || s.back().utime != to.utime) {
    *why = "IMU interval does not span the frames";
    return false;
  }
  ImuPreintegration pre(from.gyroBias(), from.accelBias(), options_.imu_noise);
  for (size_t k = 0; k + 1 < s.size(); ++k) {
    const double dt = toSeconds(s[k + 1].utime - s[k].utime);
    if (dt > options_.max_imu_gap_s) {
      *why = "IMU gap of " + std::to_string(dt) + " s";
      return false;
    }
    pre.integrate(0.5 * (s[k].gyro + s[k + 1].gyro), 0.5 * (s[k].accel + s[k + 1].accel), dt);
  }
  if (predict) {  // the new state's first guess
    Mat3 R;
    Vec3 p, v;
    pre.predict(from.pose().linear(), from.pose().translation(), from.velocity(), from.gyroBias(), from.accelBias(),
                gravity_W_, &R, &p, &v);
    to.setPose(se3::fromRotationTranslation(R, p));
    Eigen::Map<Vec3>{to.v} = v;
    std::copy(from.bg, from.bg + 3, to.bg);
    std::copy(from.ba, from.ba + 3, to.ba);
  }
  to.imu.reset(makeImuFactor(pre, gravity_W_));
  to.bias_walk.reset(
      makeBiasWalkFactor(options_.imu_noise.gyro_random_walk, options_.imu_noise.accel_random_walk, pre.duration()));
  to.wheel.reset();
  to.wheel_loss.reset();
  if (options_.use_wheel) {
    if (to.wheel_samples.empty() && !(wheel_.empty() || wheel_.front().utime > from.utime))
      samplesOver(wheel_, from.utime, to.utime, &to.wheel_samples);
    const std::vector<WheelSample>& w = to.wheel_samples;
    bool ok = w.size() >= 2;
    WheelPreintegration wp(options_.wheel_rig, options_.wheel_noise);
    for (size_t k = 0; ok && k + 1 < w.size(); ++k) {
      const double dt = toSeconds(w[k + 1].utime - w[k].utime);
      if (dt > options_.max_wheel_gap_s)
        ok = false;
      else
        wp.integrate(w[k].left_speed, w[k].right_speed, w[k + 1].left_speed, w[k + 1].right_speed, dt);
    }
    if (ok && wp.duration() > 0.0) {
      to.wheel.reset(makeWheelFactor(wp, {estimatesWheelScale(), estimatesWheelMounting()}));
      to.wheel_loss = std::make_unique<ceres::CauchyLoss>(options_.wheel_cauchy);
    } else {
      to.wheel_samples.clear();
    }
  }
  return true;
}

void SlidingWindowEstimator::addObservations(Frame& frame, const FrameFeatures& in) {
  const double focal = options_.focal;
  for (const FeatureMeasurement& m : in.features) {
    if (!m.xy.allFinite() || rejected_.count(m.id)) continue;
    const double depth = validDepth(options_, m.depth) ? m.depth : 0.0;
    auto it = features_.find(m.id);
    if (it == features_.end()) {
      auto ft = std::make_unique<Feature>();
      ft->obs.push_back({&frame, m.xy, depth, nullptr});
      if (depth > 0.0) {
        ft->rho[0] = 1.0 / depth;
        ft->has_rho = true;
        ft->depth_prior.reset(makeInverseDepthPrior(depth, depthSigma(options_, depth)));
      }
      features_.emplace(m.id, std::move(ft));
      continue;
    }
    Feature& ft = *it->second;
    if (ft.obs.back().frame == &frame) continue;  // the same id twice in one image
    ft.obs.push_back({&frame, m.xy, depth,
                      std::unique_ptr<ceres::CostFunction>(makeReprojectionFactor(
                          ft.obs.front().xy, m.xy, options_.T_I_C, focal, options_.pixel_sigma))});
  }
}

void SlidingWindowEstimator::triangulate() {
  const double min_cos = std::cos(options_.min_triangulation_angle_deg * M_PI / 180.0);
  for (auto& [id, ft] : features_) {
    if (ft->has_rho || ft->obs.size() < 2) continue;
    // the anchor against the observation with the widest angle between the two rays
    const Pose3 T_W_Ca = ft->anchor()->pose() * options_.T_I_C;
    const Vec3 ray_a = T_W_Ca.linear() * Vec3(ft->obs[0].xy.x(), ft->obs[0].xy.y(), 1.0).normalized();
    double best_cos = 1.0;
    size_t best = 0;
    for (size_t k = 1; k < ft->obs.size(); ++k) {
      const Mat3 R_W_Ck = (ft->obs[k].frame->pose() * options_.T_I_C).linear();
      const double c = ray_a.dot(R_W_Ck * Vec3(ft->obs[k].xy.x(), ft->obs[k].xy.y(), 1.0).normalized());
      if (c < best_cos) best_cos = c, best = k;
    }
    if (best == 0 || best_cos > min_cos) continue;
    // the point on ray a closest to ray b (midpoint method in the anchor camera's frame)
    const Pose3 T_Ca_Cb = T_W_Ca.inverse() * ft->obs[best].frame->pose() * options_.T_I_C;
    const Vec3 da(ft->obs[0].xy.x(), ft->obs[0].xy.y(), 1.0);
    const Vec3 db = T_Ca_Cb.linear() * Vec3(ft->obs[best].xy.x(), ft->obs[best].xy.y(), 1.0);
    const Vec3 ob = T_Ca_Cb.translation();
    // minimise |s da - (ob + u db)|: [da.da -da.db; da.db -db.db] [s u] = [da.ob db.ob]
    Eigen::Matrix2d A;
    A << da.dot(da), -da.dot(db), da.dot(db), -db.dot(db);
    const Vec2 b(da.dot(ob), db.dot(ob));
    const Vec2 su = A.colPivHouseholderQr().solve(b);
    const double z = su.x();  // depth along the anchor's z (da has z = 1)
    if (!std::isfinite(z) || su.y() <= 0.0 || !validDepth(options_, z)) continue;
    ft->rho[0] = 1.0 / z;
    ft->has_rho = true;
  }
}

std::vector<SlidingWindowEstimator::Feature*> SlidingWindowEstimator::graphFeatures() {
  std::vector<Feature*> out;
  for (auto& [id, ft] : features_) {
    ft->in_graph = false;
    if (ft->has_rho && ft->obs.size() >= 2) out.push_back(ft.get());
  }
  // longest tracks first (ties by id: deterministic), at most max_features
  std::stable_sort(out.begin(), out.end(),
                   [](const Feature* a, const Feature* b) { return a->obs.size() > b->obs.size(); });
  if (static_cast<int>(out.size()) > options_.max_features) out.resize(options_.max_features);
  for (Feature* ft : out) ft->in_graph = true;
  return out;
}

template <class Add>
void SlidingWindowEstimator::forEachFactor(const std::vector<Feature*>& features, Add&& add) const {
  if (prior_factor_) add(prior_factor_.get(), nullptr, prior_->blocks);
  for (size_t k = 0; k < window_.size(); ++k) {
    Frame& f = *window_[k];
    for (size_t i = 0; i < f.priors.size(); ++i) add(f.priors[i].get(), nullptr, f.prior_blocks[i]);
    if (k == 0) continue;
    Frame& e = *window_[k - 1];
    if (f.imu) add(f.imu.get(), nullptr, imuFactorBlocks(e.inertial(), f.inertial()));
    if (f.bias_walk) add(f.bias_walk.get(), nullptr, biasWalkBlocks(e.inertial(), f.inertial()));
    if (f.wheel) add(f.wheel.get(), f.wheel_loss.get(), wheelBlocks(e, f));
  }
  for (Feature* ft : features) {
    Frame& a = *ft->anchor();
    for (size_t k = 1; k < ft->obs.size(); ++k)
      add(ft->obs[k].cost.get(), reprojection_loss_.get(),
          {a.q, a.p, ft->obs[k].frame->q, ft->obs[k].frame->p, ft->rho});
    if (ft->depth_prior) add(ft->depth_prior.get(), nullptr, {ft->rho});
  }
}

void SlidingWindowEstimator::optimize(const std::vector<Feature*>& features) {
  ceres::Problem problem(nonOwningProblemOptions());
  static RightQuaternionManifold manifold;
  for (auto& f : window_) {
    problem.AddParameterBlock(f->q, 4, &manifold);
    for (double* b : {f->p, f->v, f->bg, f->ba}) problem.AddParameterBlock(b, 3);
  }
  forEachFactor(features, [&](ceres::CostFunction* cost, ceres::LossFunction* loss, std::vector<double*> blocks) {
    problem.AddResidualBlock(cost, loss, blocks);
  });
  for (Feature* ft : features) {
    problem.SetParameterLowerBound(ft->rho, 0, 1.0 / options_.max_depth);
    problem.SetParameterUpperBound(ft->rho, 0, 1.0 / options_.min_depth);
  }
  solveWindow(&problem, options_.solver_iterations);
}

int SlidingWindowEstimator::rejectOutliers() {
  const double limit = options_.outlier_px / options_.focal;
  std::vector<uint64_t> drop;
  for (auto& [id, ft] : features_) {
    if (!ft->in_graph) continue;
    const Pose3 T_a = ft->anchor()->pose();
    for (size_t k = 1; k < ft->obs.size(); ++k) {
      const Vec3 p = predictInCamera(ft->obs[0].xy, ft->rho[0], T_a, ft->obs[k].frame->pose(), options_.T_I_C);
      if (!(p.z() > 1e-6) || (p.head<2>() / p.z() - ft->obs[k].xy).norm() > limit) {
        drop.push_back(id);
        break;
      }
    }
  }
  for (uint64_t id : drop) {
    rejected_.insert(id);
    eraseFeature(id);
  }
  return static_cast<int>(drop.size());
}

void SlidingWindowEstimator::eraseFeature(uint64_t id) { features_.erase(id); }

void SlidingWindowEstimator::marginalizeOldest() {
  Frame& a = *window_[0];
  Frame& b = *window_[1];
  Marginalizer m;
  for (auto& f : window_) m.setQuaternion(f->q);
  if (prior_factor_) m.addFactor(prior_factor_.get(), prior_->blocks);
  for (size_t i = 0; i < a.priors.size(); ++i) m.addFactor(a.priors[i].get(), a.prior_blocks[i]);
  std::set<const double*> drop =
      addOldestInertialFactors(&m, a.inertial(), b.inertial(), b.imu.get(), b.bias_walk.get());
  if (b.wheel) m.addFactor(b.wheel.get(), wheelBlocks(a, b), b.wheel_loss.get());
  // the scales and the mounting are not dropped: what these factors said about them stays in the prior
  // The features anchored here leave with it: what they said about the states that stay goes into
  // the prior (those in the last optimisation); a later observation of the same track starts anew.
  std::vector<uint64_t> leaving;
  for (auto& [id, ft] : features_) {
    if (ft->anchor() != &a) continue;
    leaving.push_back(id);
    if (!ft->in_graph) continue;
    for (size_t k = 1; k < ft->obs.size(); ++k)
      m.addFactor(ft->obs[k].cost.get(), {a.q, a.p, ft->obs[k].frame->q, ft->obs[k].frame->p, ft->rho},
                  reprojection_loss_.get());
    if (ft->depth_prior) m.addFactor(ft->depth_prior.get(), {ft->rho});
    drop.insert(ft->rho);
  }
  prior_ = m.marginalize(drop);
  prior_factor_ = prior_ ? std::make_unique<MarginalPriorFactor>(prior_) : nullptr;
  for (uint64_t id : leaving) features_.erase(id);
  b.imu.reset();
  b.bias_walk.reset();
  b.wheel.reset();
  b.wheel_loss.reset();
  b.imu_samples.clear();
  b.wheel_samples.clear();
  window_.pop_front();
}

void SlidingWindowEstimator::dropSecondNewest() {
  const size_t n = window_.size();
  Frame& s = *window_[n - 2];
  Frame& c = *window_[n - 1];
  // Its blocks in the marginal prior are marginalised out of it (its other factors are dropped).
  if (prior_ && std::find(prior_->blocks.begin(), prior_->blocks.end(), s.q) != prior_->blocks.end()) {
    Marginalizer m;
    for (auto& f : window_) m.setQuaternion(f->q);
    m.addFactor(prior_factor_.get(), prior_->blocks);
    prior_ = m.marginalize({s.q, s.p, s.v, s.bg, s.ba});
    prior_factor_ = prior_ ? std::make_unique<MarginalPriorFactor>(prior_) : nullptr;
  }
  // its observations go; features anchored there move to their next observation
  std::vector<uint64_t> gone;
  for (auto& [id, ft] : features_) {
    auto it =
        std::find_if(ft->obs.begin(), ft->obs.end(), [&](const Feature::Observation& o) { return o.frame == &s; });
    if (it == ft->obs.end()) continue;
    if (it != ft->obs.begin()) {
      ft->obs.erase(it);
      continue;
    }
    if (ft->obs.size() < 2) {
      gone.push_back(id);
      continue;
    }
    // re-anchor at the next observation, the inverse depth carried over with the current poses
    Feature::Observation& next = ft->obs[1];
    double rho = 0.0;
    if (next.depth > 0.0) {
      rho = 1.0 / next.depth;
    } else if (ft->has_rho) {
      const Vec3 p = predictInCamera(ft->obs[0].xy, ft->rho[0], s.pose(), next.frame->pose(), options_.T_I_C);
      if (p.z() > 0.0 && validDepth(options_, p.z())) rho = 1.0 / p.z();
    }
    ft->obs.erase(ft->obs.begin());
    ft->obs.front().cost.reset();
    ft->has_rho = rho > 0.0;
    ft->rho[0] = rho;
    ft->depth_prior.reset(
        ft->obs.front().depth > 0.0
            ? makeInverseDepthPrior(ft->obs.front().depth, depthSigma(options_, ft->obs.front().depth))
            : nullptr);
    for (size_t k = 1; k < ft->obs.size(); ++k)
      ft->obs[k].cost.reset(makeReprojectionFactor(ft->obs.front().xy, ft->obs[k].xy, options_.T_I_C, options_.focal,
                                                   options_.pixel_sigma));
  }
  for (uint64_t id : gone) features_.erase(id);
  // the IMU and wheel intervals merge: [e, s] + [s, c] becomes [e, c]
  std::vector<ImuSample> imu = s.imu_samples;
  imu.insert(imu.end(), c.imu_samples.begin() + 1, c.imu_samples.end());
  c.imu_samples = std::move(imu);
  if (!s.wheel_samples.empty() && !c.wheel_samples.empty()) {
    std::vector<WheelSample> w = s.wheel_samples;
    w.insert(w.end(), c.wheel_samples.begin() + 1, c.wheel_samples.end());
    c.wheel_samples = std::move(w);
  } else {
    c.wheel_samples.clear();
  }
  Frame& e = *window_[n - 3];
  std::string why;
  connect(e, c, false, &why);  // c keeps its estimate; the samples are there, so this cannot fail
  window_.erase(window_.begin() + static_cast<long>(n - 2));
}

Mat6 SlidingWindowEstimator::newestPoseCovariance(const std::vector<Feature*>& features) const {
  Marginalizer m;
  for (auto& f : window_) m.setQuaternion(f->q);
  forEachFactor(features, [&](ceres::CostFunction* cost, ceres::LossFunction* loss, std::vector<double*> blocks) {
    m.addFactor(cost, std::move(blocks), loss);
  });
  const Frame& c = *window_.back();
  Eigen::MatrixXd info;
  if (!m.marginalInformation({c.q, c.p}, &info)) return Mat6::Identity();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(info);
  const Eigen::VectorXd ev = es.eigenvalues().cwiseMax(1e-9);
  return Mat6(es.eigenvectors() * ev.cwiseInverse().asDiagonal() * es.eigenvectors().transpose());
}

bool SlidingWindowEstimator::poseAt(int64_t t, Pose3* pose) const {
  if (window_.empty() || t < window_.front()->utime) return false;
  const Frame& last = *window_.back();
  if (t <= last.utime) {
    size_t k = 0;  // the first frame not before t: one exists, and k > 0 unless it is at t
    while (window_[k]->utime < t) ++k;
    if (window_[k]->utime == t) {
      *pose = window_[k]->pose();
      return true;
    }
    const Frame& a = *window_[k - 1];
    const Frame& b = *window_[k];
    const double s = static_cast<double>(t - a.utime) / static_cast<double>(b.utime - a.utime);
    const Pose3 Ta = a.pose(), Tb = b.pose();
    const Mat3 R = Ta.linear() * so3::Exp(s * so3::Log(Mat3(Ta.linear().transpose() * Tb.linear())));
    *pose = se3::fromRotationTranslation(R, (1.0 - s) * Ta.translation() + s * Tb.translation());
    return true;
  }
  std::vector<ImuSample> samples;
  if (!samplesOver(imu_, last.utime, t, &samples)) return false;
  ImuPreintegration pre(last.gyroBias(), last.accelBias(), options_.imu_noise);
  for (size_t k = 0; k + 1 < samples.size(); ++k)
    pre.integrate(0.5 * (samples[k].gyro + samples[k + 1].gyro), 0.5 * (samples[k].accel + samples[k + 1].accel),
                  toSeconds(samples[k + 1].utime - samples[k].utime));
  Mat3 R;
  Vec3 p, v;
  pre.predict(last.pose().linear(), last.pose().translation(), last.velocity(), last.gyroBias(), last.accelBias(),
              gravity_W_, &R, &p, &v);
  *pose = se3::fromRotationTranslation(R, p);
  return true;
}

bool SlidingWindowEstimator::gyroRotation(int64_t t0, int64_t t1, Mat3* R) const {
  std::vector<ImuSample> samples;
  if (imu_.empty() || imu_.front().utime > t0 || !samplesOver(imu_, t0, t1, &samples)) return false;
  const Vec3 bg = window_.empty() ? Vec3::Zero() : window_.back()->gyroBias();
  *R = Mat3::Identity();
  for (size_t k = 0; k + 1 < samples.size(); ++k)
    *R = *R * so3::Exp((0.5 * (samples[k].gyro + samples[k + 1].gyro) - bg) *
                       toSeconds(samples[k + 1].utime - samples[k].utime));
  return true;
}

std::vector<double*> SlidingWindowEstimator::wheelBlocks(Frame& a, Frame& b) const {
  std::vector<double*> blocks = {a.q, a.p, b.q, b.p};  // in makeWheelFactor's order
  if (estimatesWheelScale()) blocks.push_back(wheel_scale_);
  if (estimatesWheelMounting()) blocks.push_back(wheel_mounting_);
  return blocks;
}

VisualState SlidingWindowEstimator::stateOf(const Frame& f) const {
  VisualState s;
  s.utime = f.utime;
  s.pose = f.pose();
  s.velocity = f.velocity();
  s.gyro_bias = f.gyroBias();
  s.accel_bias = f.accelBias();
  return s;
}

}  // namespace livo::vio_feature
