#include "livo/lio_graph/lio_graph_estimator.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "livo/graph_factors.hpp"
#include "livo/inertial_window.hpp"
#include "livo/lio_graph/plane_factor.hpp"
#include "livo/plane.hpp"
#include "livo/result_note.hpp"
#include "livo/sample_interval.hpp"
#include "livo/text_format.hpp"
#include "livo/time.hpp"
#include "livo/voxel_downsample.hpp"

namespace livo::lio_graph {

namespace {

/// A pose's information [dtheta (right), dp] in a world turned by R: the rotation error is
/// body-frame and stays, the position error turns with the world.
Mat6 turnedInformation(const Mat6& information, const Mat3& R) {
  Mat6 A = Mat6::Identity();
  A.bottomRightCorner<3, 3>() = R;
  return A * information * A.transpose();
}

}  // namespace

const char* toString(GraphScanResult::Status s) {
  switch (s) {
    case GraphScanResult::Status::kInitializing: return "initializing";
    case GraphScanResult::Status::kRejected: return "rejected";
    case GraphScanResult::Status::kMapInitialized: return "map initialized";
    case GraphScanResult::Status::kTracked: return "tracked";
    case GraphScanResult::Status::kPredicted: return "predicted";
  }
  return "?";
}

/// A plane of the scene: c is the vector from `anchor` to its closest point (graph_factors.hpp).
struct LioGraphEstimator::PlaneLandmark {
  double c[3] = {0, 0, 1};
  Vec3 anchor = Vec3::Zero();
  int observers = 0;  // window states that observe it
  /// The plane with `from` (a point on the anchor's side) on its positive side.
  Plane seenFrom() const {
    const Vec3 cv(c[0], c[1], c[2]);
    const double len = cv.norm();
    Plane pl;
    pl.normal = -cv / len;
    pl.offset = pl.normal.dot(-anchor) + len;  // n'.x + d' = 0, n' = -c/|c|, d' = n.a + |c|
    return pl;
  }
};

/// One state of the window and the factors that end at it (owned here; the problem is rebuilt for
/// every optimisation, so nothing else owns them).
struct LioGraphEstimator::Node {
  int64_t utime = 0;
  double q[4] = {0, 0, 0, 1};
  double p[3] = {0, 0, 0};
  double v[3] = {0, 0, 0};
  double bg[3] = {0, 0, 0};
  double ba[3] = {0, 0, 0};
  Vec3 last_gyro = Vec3::Zero();
  std::unique_ptr<ceres::CostFunction> imu, bias_walk, wheel, lidar, visual;
  std::unique_ptr<ceres::LossFunction> wheel_loss, visual_loss;
  // What the factors holding world-frame quantities were made from, to remake them when a loop
  // correction moves the world (the wheel, visual and bias factors are relative: they never move).
  std::optional<ImuPreintegration> imu_preintegration;  // its factor holds the world gravity
  Pose3 lidar_pose = Pose3::Identity();                 // the matched W_T_I ...
  Mat6 lidar_information = Mat6::Zero();                // ... and its information [dtheta (right), dp]
  /// A prior of the first state (the initialisation).
  struct Unary {
    enum class Kind { kPose, kVelocity, kBias, kWheelScale, kWheelMounting, kVisualScale } kind;
    std::vector<double*> blocks;
    Pose3 pose = Pose3::Identity();  // kPose: W_T_I and its information
    Mat6 information = Mat6::Zero();
    // kVelocity (world frame), kBias, kWheelMounting (body frame); kWheelScale: head<2>, sigma(0); kVisualScale: (0)
    Vec3 mean = Vec3::Zero(), sigma = Vec3::Ones();
    std::optional<Mat3> covariance;  // kBias: a full covariance in place of the per-axis sigmas
    std::unique_ptr<ceres::CostFunction> cost;
    void remake() {
      switch (kind) {
        case Kind::kPose: cost.reset(makePoseFactor(pose, information)); break;
        case Kind::kWheelScale: cost.reset(makeWheelScalePrior(mean.head<2>(), sigma(0))); break;
        case Kind::kWheelMounting: cost.reset(makeWheelMountingPrior(mean, sigma(0))); break;
        case Kind::kVisualScale: cost.reset(makeScalarPriorFactor(mean(0), sigma(0))); break;
        default: cost.reset(covariance ? makeCorrelatedVectorPriorFactor(mean, *covariance) : makeVectorPriorFactor(mean, sigma));
      }
    }
  };
  std::vector<Unary> priors;  // the first state's
  struct PlaneObservation {
    PlaneLandmark* landmark;
    Vec3 normal;  // the measured plane, body frame (n.x + offset = 0) ...
    double offset;
    double sigma_angle, sigma_distance;  // ... and its sigmas
    std::unique_ptr<ceres::CostFunction> cost;
    /// The factor against the landmark's current anchor.
    void remake() { cost.reset(makePlaneFactor(landmark->anchor, normal, offset, sigma_angle, sigma_distance)); }
  };
  std::vector<PlaneObservation> planes;

  Pose3 pose() const { return poseFromBlocks(q, p); }
  void setPose(const Pose3& T) {
    const Eigen::Quaterniond r = Eigen::Quaterniond(T.linear()).normalized();
    std::copy(r.coeffs().data(), r.coeffs().data() + 4, q);
    const Vec3 t = T.translation();
    std::copy(t.data(), t.data() + 3, p);
  }
  std::vector<double*> blocks() { return {q, p, v, bg, ba}; }
  InertialBlocks inertial() { return {q, p, v, bg, ba}; }
};

LioGraphEstimator::LioGraphEstimator(LioGraphOptions options)
    : options_(std::move(options)), keyframe_selector_(options_.keyframe), gravity_W_(0.0, 0.0, -options_.gravity) {}
LioGraphEstimator::~LioGraphEstimator() = default;

void LioGraphEstimator::reset() {
  frame_ = OdometryFrame{frame_.epoch + 1, 0, Pose3::Identity()};
  gravity_W_ = Vec3(0.0, 0.0, -options_.gravity);
  window_.clear();
  landmarks_.clear();
  prior_.reset();
  prior_factor_.reset();
  keyframes_.clear();
  map_.rebuild({}, {});
  keyframe_selector_.reset();
  last_sweep_end_ = -1;
}

bool LioGraphEstimator::addImu(const ImuSample& s, std::string* why) {
  if (!s.gyro.allFinite() || !s.accel.allFinite()) {
    if (why) *why = "non-finite IMU sample";
    return false;
  }
  if (!imu_.empty() && s.utime <= imu_.back().utime) {
    if (why) *why = "IMU sample not later than the previous one";
    return false;
  }
  if (!imu_.empty() && toSeconds(s.utime - imu_.back().utime) > options_.max_imu_gap_s && initialized()) {
    const double gap = toSeconds(s.utime - imu_.back().utime);
    reset();  // the propagation across such a gap is worthless: a new epoch
    if (why) *why = "IMU gap of " + formatSignificant(gap) + " s";
  }
  imu_.push_back(s);
  // keep what the newest state and the initialisation window need
  const int64_t keep_from = initialized() ? window_.back()->utime : s.utime - toUtime(options_.init.window_s + 1.0);
  dropImuBefore(keep_from);
  return true;
}

bool LioGraphEstimator::addWheel(const WheelSample& s, std::string* why) {
  if (!std::isfinite(s.left_speed) || !std::isfinite(s.right_speed)) {
    if (why) *why = "non-finite wheel speed";
    return false;
  }
  if (!wheel_.empty() && s.utime <= wheel_.back().utime) {
    if (why) *why = "wheel reading not later than the previous one";
    return false;
  }
  wheel_.push_back(s);
  const int64_t keep_from = initialized() ? window_.back()->utime : s.utime - toUtime(1.0);
  while (wheel_.size() > 2 && wheel_[1].utime <= keep_from) wheel_.pop_front();
  return true;
}

void LioGraphEstimator::dropImuBefore(int64_t utime) {
  while (imu_.size() > 2 && imu_[1].utime <= utime) imu_.pop_front();
}

bool LioGraphEstimator::addVisualState(const VisualSample& s, std::string* why) { return visual_.add(s, why); }

bool LioGraphEstimator::initialize(int64_t t_end, std::string* note) {
  const std::vector<ImuSample> window = imuStartWindow(imu_, t_end, options_.init.window_s);
  if (!startWindowFilled(window, options_.init.window_s)) {
    *note = kWaitingForImuStartWindow;
    return false;
  }
  ImuInitOptions init = options_.init;
  init.gravity = options_.gravity;
  const ImuInitResult r = initializeImu(window, init);
  if (!r.ok) {
    *note = "IMU initialisation failed: " + r.message;
    return false;
  }
  const StartStateSigmas sigma = r.static_start ? restStartSigmas(init) : movingStartSigmas(init);
  const Mat3 accel_bias_covariance = r.covariance.block<3, 3>(FilterState::kAccelBias, FilterState::kAccelBias);
  window_.push_back(startNode(t_end, r.state, window.back().gyro, sigma, accel_bias_covariance));
  *note = r.static_start ? "initialised at rest" : "initialised in motion";
  return true;
}

std::unique_ptr<LioGraphEstimator::Node> LioGraphEstimator::startNode(int64_t t_end, const FilterState& state,
                                                                      const Vec3& last_gyro,
                                                                      const StartStateSigmas& sigma,
                                                                      const Mat3& accel_bias_covariance) {
  auto n = std::make_unique<Node>();
  n->utime = t_end;
  n->setPose(se3::fromRotationTranslation(state.rot, Vec3::Zero()));
  Eigen::Map<Vec3>(n->bg) = state.gyro_bias;
  Eigen::Map<Vec3>(n->ba) = state.accel_bias;
  n->last_gyro = last_gyro;
  // the gauge (yaw, position) held firmly, roll and pitch, velocity and biases as initialised
  const Mat6 info = startPoseInformation(sigma.rotation, options_.init.yaw_std, options_.init.pos_std);
  using Unary = Node::Unary;
  n->priors.resize(4);
  n->priors[0].kind = Unary::Kind::kPose;
  n->priors[0].blocks = {n->q, n->p};
  n->priors[0].pose = n->pose();
  n->priors[0].information = info;
  // isotropic: a loop correction turns the mean only
  n->priors[1].kind = Unary::Kind::kVelocity;
  n->priors[1].blocks = {n->v};
  n->priors[1].sigma = Vec3::Constant(sigma.velocity);
  n->priors[2].kind = Unary::Kind::kBias;
  n->priors[2].blocks = {n->bg};
  n->priors[2].mean = state.gyro_bias;
  n->priors[2].sigma = Vec3::Constant(sigma.gyro_bias);
  n->priors[3].kind = Unary::Kind::kBias;
  n->priors[3].blocks = {n->ba};
  n->priors[3].mean = state.accel_bias;
  n->priors[3].covariance = accel_bias_covariance;
  addCalibrationPriors(n.get());
  for (Unary& u : n->priors) u.remake();
  return n;
}

void LioGraphEstimator::addCalibrationPriors(Node* n) {
  using Unary = Node::Unary;
  // the wheel scales keep what an earlier epoch learned, held with the prior's sigma
  if (estimatesWheelScale()) {
    n->priors.emplace_back();
    Unary& u = n->priors.back();
    u.kind = Unary::Kind::kWheelScale;
    u.blocks = {wheel_scale_};
    u.mean.head<2>() = wheelScale();
    u.sigma.setConstant(options_.wheel_scale_std);
  }
  // the wheel frame's mounting likewise, around what an earlier epoch learned, with the rig's sigma
  if (estimatesWheelMounting()) {
    n->priors.emplace_back();
    Unary& u = n->priors.back();
    u.kind = Unary::Kind::kWheelMounting;
    u.blocks = {wheel_mounting_};
    u.mean = wheelMounting();
    u.sigma.setConstant(options_.wheel_rig.mountingStdRad());
  }
  // the visual motion's scale likewise
  if (estimatesVisualScale()) {
    n->priors.emplace_back();
    Unary& u = n->priors.back();
    u.kind = Unary::Kind::kVisualScale;
    u.blocks = {visual_scale_};
    u.mean(0) = visual_scale_[0];
    u.sigma.setConstant(options_.visual_scale_std);
  }
}

bool LioGraphEstimator::preintegrate(int64_t t_end, ImuPreintegration* pre, std::vector<ImuStep>* steps,
                                     Vec3* last_gyro) const {
  const Node& n = *window_.back();
  std::vector<ImuSample> s;
  if (!samplesOver(imu_, n.utime, t_end, &s)) return false;
  const Mat3 R0 = n.pose().linear();
  const Vec3 p0(n.p[0], n.p[1], n.p[2]), v0(n.v[0], n.v[1], n.v[2]);
  const Vec3 bg(n.bg[0], n.bg[1], n.bg[2]), ba(n.ba[0], n.ba[1], n.ba[2]);
  const Vec3& g = gravity_W_;
  *pre = ImuPreintegration(bg, ba, options_.imu_noise);
  steps->clear();
  steps->push_back({n.utime, n.pose()});
  for (size_t k = 0; k + 1 < s.size(); ++k) {
    const double dt = toSeconds(s[k + 1].utime - s[k].utime);
    if (dt <= 0.0) continue;
    pre->integrate(0.5 * (s[k].gyro + s[k + 1].gyro), 0.5 * (s[k].accel + s[k + 1].accel), dt);
    Mat3 R;
    Vec3 p, v;
    pre->predict(R0, p0, v0, bg, ba, g, &R, &p, &v);
    steps->push_back({s[k + 1].utime, se3::fromRotationTranslation(R, p)});
  }
  *last_gyro = s.back().gyro;
  return true;
}

std::unique_ptr<WheelPreintegration> LioGraphEstimator::wheelBetween(int64_t t0, int64_t t1) const {
  std::vector<WheelSample> s;
  if (!samplesOver(wheel_, t0, t1, &s)) return nullptr;
  if (wheel_.front().utime > t0) return nullptr;  // the readings do not reach back to t0
  auto pre = std::make_unique<WheelPreintegration>(options_.wheel_rig, options_.wheel_noise);
  for (size_t k = 0; k + 1 < s.size(); ++k) {
    const double dt = toSeconds(s[k + 1].utime - s[k].utime);
    if (dt > options_.max_wheel_gap_s) return nullptr;
    pre->integrate(s[k].left_speed, s[k].right_speed, s[k + 1].left_speed, s[k + 1].right_speed, dt);
  }
  return pre->duration() > 0.0 ? std::move(pre) : nullptr;
}

void LioGraphEstimator::deskew(const LidarScan& scan, int64_t t_first, const std::vector<ImuStep>& steps,
                               std::vector<Vec3>* body, std::vector<uint32_t>* index, std::vector<int16_t>* ring,
                               std::vector<float>* time) const {
  const Pose3 T_end_inv = steps.back().pose.inverse();
  const Pose3& T_I_L = options_.extrinsics.T_I_L;
  const double end_offset = toSeconds(steps.back().utime - t_first);
  const size_t n = std::min(scan.points.size(), scan.time_offset.size());
  const bool has_ring = scan.ring.size() == scan.points.size();
  const double min2 = options_.min_range * options_.min_range, max2 = options_.max_range * options_.max_range;
  size_t seg = 0;
  for (size_t j = 0; j < n; ++j) {
    const Vec3& pl = scan.points[j];
    const float off = scan.time_offset[j];
    if (!pl.allFinite() || !std::isfinite(off) || off < 0.0f || off > end_offset + 1e-6) continue;
    const double r2 = pl.squaredNorm();
    if (r2 < min2 || r2 > max2) continue;
    const int64_t t = t_first + toUtime(off);
    // the predicted pose at t (held before the first step), between two IMU steps
    Pose3 T_W_I;
    if (t <= steps.front().utime) {
      T_W_I = steps.front().pose;
    } else {
      if (seg >= steps.size() - 1 || steps[seg].utime > t) seg = 0;
      while (seg + 1 < steps.size() - 1 && steps[seg + 1].utime < t) ++seg;
      const ImuStep& a = steps[seg];
      const ImuStep& b = steps[std::min(seg + 1, steps.size() - 1)];
      const double s =
          b.utime > a.utime ? std::clamp(static_cast<double>(t - a.utime) / (b.utime - a.utime), 0.0, 1.0) : 1.0;
      T_W_I = se3::interpolate(a.pose, b.pose, s);
    }
    body->push_back(T_end_inv * (T_W_I * (T_I_L * pl)));
    index->push_back(static_cast<uint32_t>(j));
    ring->push_back(has_ring ? scan.ring[j] : int16_t{-1});
    time->push_back(off);
  }
}

GraphScanResult LioGraphEstimator::addScan(const LidarScan& scan, const SweepTiming& timing) {
  GraphScanResult res;
  const int64_t t_end = timing.end_utime, t_first = timing.start_utime;
  res.utime = t_end;
  res.sweep_start_utime = t_first;
  if (t_end <= last_sweep_end_) {
    res.status = GraphScanResult::Status::kRejected;
    res.message = "sweep ends before the previous one";
    return res;
  }
  const bool seeding = !initialized();
  if (seeding && !initialize(t_end, &res.message)) {
    res.status = GraphScanResult::Status::kInitializing;
    return res;
  }
  last_sweep_end_ = t_end;

  // 1. preintegration to the sweep end and the predicted poses (deskewing)
  ImuPreintegration pre(Vec3::Zero(), Vec3::Zero(), options_.imu_noise);
  std::vector<ImuStep> steps;
  Vec3 last_gyro = window_.back()->last_gyro;
  if (seeding) {
    steps = {{t_end, window_.back()->pose()}};
  } else if (!preintegrate(t_end, &pre, &steps, &last_gyro)) {
    res.status = GraphScanResult::Status::kRejected;
    res.message = "the IMU does not reach the sweep end";
    return res;
  }
  // The visual subsystem's motion over the sweep, where it covers it, replaces the IMU's
  // translation (which rests on the graph's velocity); the rotation stays the gyro's.
  if (!seeding && options_.use_visual_motion) {
    if (const auto p_visual = visualPositions(steps)) {
      for (size_t k = 0; k < steps.size(); ++k) steps[k].pose.translation() = (*p_visual)[k];
      res.visual_motion = true;
    }
  }

  // 2. deskewed points and their features
  std::vector<Vec3> body;
  RingCloud cloud;
  deskew(scan, t_first, steps, &body, &res.input_index, &cloud.ring, &cloud.time_offset);
  res.num_points = static_cast<int>(body.size());
  ScanFeatures features = bodyFrameFeatures(body, std::move(cloud));

  Node* newest = nullptr;
  if (seeding) {
    newest = window_.back().get();
    res.status = GraphScanResult::Status::kMapInitialized;
    observePlanes(body, newest, &res);
  } else {
    // 3. and 4.
    newest = addState(t_end, pre, res.visual_motion ? &steps.back().pose : nullptr, last_gyro, features, body, &res);
  }
  reportState(*newest, body, &res);

  // 5. keyframes: the local map grows where the body has moved
  if (res.status != GraphScanResult::Status::kPredicted && keyframe_selector_.check(res.pose))
    addKeyframe(scan, body, std::move(features), newest, &res);
  return res;
}

std::optional<std::vector<Vec3>> LioGraphEstimator::visualPositions(const std::vector<ImuStep>& steps) const {
  const Pose3 T_prev = window_.back()->pose();
  std::vector<Vec3> p_visual(steps.size());
  bool covered = true;
  for (size_t k = 0; k < steps.size() && covered; ++k) {
    Pose3 rel;
    covered = visual_.relative(window_.back()->utime, steps[k].utime, &rel);
    p_visual[k] = T_prev * rel.translation();
  }
  if (!covered) return std::nullopt;
  return p_visual;
}

ScanFeatures LioGraphEstimator::bodyFrameFeatures(const std::vector<Vec3>& body, RingCloud cloud) const {
  const Pose3 T_L_I = options_.extrinsics.T_I_L.inverse();
  cloud.points.reserve(body.size());
  for (const Vec3& b : body) cloud.points.push_back(T_L_I * b);
  ScanFeatures features = extractFeatures(cloud, options_.features);
  for (Vec3& e : features.edges) e = options_.extrinsics.T_I_L * e;
  for (Vec3& s : features.surfaces) s = options_.extrinsics.T_I_L * s;
  return features;
}

LioGraphEstimator::Node* LioGraphEstimator::addState(int64_t t_end, const ImuPreintegration& pre,
                                                     const Pose3* visual_guess, const Vec3& last_gyro,
                                                     const ScanFeatures& features, const std::vector<Vec3>& body,
                                                     GraphScanResult* res) {
  // 3. scan-to-map matching from the prediction
  const Node& prev = *window_.back();
  std::unique_ptr<Node> n = predictedState(prev, t_end, pre, visual_guess, last_gyro);
  addLidarFactor(matchScan(map_, features, n->pose(), options_.matching), n.get(), res);
  // 4. the new state's factors, the window optimised, the oldest state marginalised
  addMotionFactors(prev, pre, n.get(), res);
  observePlanes(body, n.get(), res);
  window_.push_back(std::move(n));
  Node* newest = window_.back().get();
  optimize();
  while (static_cast<int>(window_.size()) > std::max(2, options_.window_states)) marginalizeOldest();
  updateKeyframePoses();
  dropImuBefore(newest->utime);
  return newest;
}

std::unique_ptr<LioGraphEstimator::Node> LioGraphEstimator::predictedState(const Node& prev, int64_t t_end,
                                                                           const ImuPreintegration& pre,
                                                                           const Pose3* visual_guess,
                                                                           const Vec3& last_gyro) const {
  auto n = std::make_unique<Node>();
  n->utime = t_end;
  Mat3 R;
  Vec3 p, v;
  pre.predict(prev.pose().linear(), Vec3(prev.p[0], prev.p[1], prev.p[2]), Vec3(prev.v[0], prev.v[1], prev.v[2]),
              pre.gyroBias(), pre.accelBias(), gravity_W_, &R, &p, &v);
  n->setPose(visual_guess ? *visual_guess : se3::fromRotationTranslation(R, p));
  Eigen::Map<Vec3>(n->v) = v;
  std::copy(prev.bg, prev.bg + 3, n->bg);
  std::copy(prev.ba, prev.ba + 3, n->ba);
  n->last_gyro = last_gyro;
  return n;
}

void LioGraphEstimator::addLidarFactor(const ScanMatchResult& match, Node* n, GraphScanResult* res) const {
  res->edge_residuals = match.edge_residuals;
  res->surface_residuals = match.surface_residuals;
  res->degenerate = match.degenerate;
  res->weakest_direction = match.weakest;
  if (match.valid) {
    n->setPose(match.T_W_I);
    n->lidar_pose = match.T_W_I;
    n->lidar_information =
        match.hessian * (options_.lidar_information_scale / (options_.lidar_point_sigma * options_.lidar_point_sigma));
    n->lidar.reset(makePoseFactor(n->lidar_pose, n->lidar_information));
    res->status = GraphScanResult::Status::kTracked;
  } else {
    res->status = GraphScanResult::Status::kPredicted;
    res->degenerate = true;
    appendNote(&res->message, "too few matches with the local map (" + std::to_string(match.edge_residuals) +
                                  " edge, " + std::to_string(match.surface_residuals) + " surface): IMU prediction");
  }
}

void LioGraphEstimator::addMotionFactors(const Node& prev, const ImuPreintegration& pre, Node* n,
                                         GraphScanResult* res) const {
  n->imu_preintegration = pre;
  n->imu.reset(makeImuFactor(pre, gravity_W_));
  n->bias_walk.reset(
      makeBiasWalkFactor(options_.imu_noise.gyro_random_walk, options_.imu_noise.accel_random_walk, pre.duration()));
  if (options_.use_wheel) {
    if (auto w = wheelBetween(prev.utime, n->utime)) {
      n->wheel.reset(makeWheelFactor(*w, {estimatesWheelScale(), estimatesWheelMounting()}));
      n->wheel_loss = std::make_unique<ceres::CauchyLoss>(options_.wheel_cauchy);
    } else {
      appendNote(&res->message, "no wheel readings over the sweep");
    }
  }
  if (res->visual_motion && options_.visual_factor) {
    // the visual subsystem's motion from the previous state to this one (the deskew's last step)
    Pose3 rel;
    visual_.relative(prev.utime, n->utime, &rel);
    n->visual.reset(estimatesVisualScale() ? makeScaledRelativePoseFactor(rel, visualInformation(rel))
                                           : makeRelativePoseFactor(rel, visualInformation(rel)));
    n->visual_loss = std::make_unique<ceres::CauchyLoss>(options_.visual_cauchy);
    res->visual_factor = true;
  }
}

void LioGraphEstimator::reportState(const Node& newest, const std::vector<Vec3>& body, GraphScanResult* res) {
  res->pose = newest.pose();
  res->velocity = Vec3(newest.v[0], newest.v[1], newest.v[2]);
  res->gyro_bias = Vec3(newest.bg[0], newest.bg[1], newest.bg[2]);
  res->accel_bias = Vec3(newest.ba[0], newest.ba[1], newest.ba[2]);
  res->angular_velocity = newest.last_gyro - res->gyro_bias;
  res->wheel_scale = wheelScale();
  res->wheel_mounting = wheelMounting();
  res->pose_covariance = newestPoseCovariance();
  res->world_points.reserve(body.size());
  for (const Vec3& b : body) res->world_points.push_back(res->pose * b);
}

void LioGraphEstimator::addKeyframe(const LidarScan& scan, const std::vector<Vec3>& body, ScanFeatures features,
                                    const Node* newest, GraphScanResult* res) {
  StoredKeyframe s;
  s.kf.id = next_keyframe_id_++;
  s.kf.utime = res->utime;
  s.kf.pose = res->pose;
  s.kf.pose_covariance = res->pose_covariance;
  const bool has_intensity = scan.intensity.size() == scan.points.size();
  for (size_t i : firstPointPerVoxel(body, options_.keyframe.cloud_voxel)) {
    s.kf.cloud.push_back(body[i]);
    s.kf.intensity.push_back(has_intensity ? scan.intensity[res->input_index[i]] : 0.0f);
  }
  s.edges = std::move(features.edges);
  s.surfaces = std::move(features.surfaces);
  s.node = newest;
  res->is_keyframe = true;
  res->keyframe = s.kf;
  s.kf.cloud = {};  // the map needs the features only
  s.kf.intensity = {};
  keyframes_.push_back(std::move(s));
  pruneStoredKeyframes();
  rebuildLocalMap(keyframes_.back().kf.pose.translation());
}

void LioGraphEstimator::observePlanes(const std::vector<Vec3>& body, Node* node, GraphScanResult* res) {
  if (!options_.planar_factors) return;
  std::vector<Vec3> cloud;
  for (size_t i : firstPointPerVoxel(body, options_.plane_cloud_voxel)) cloud.push_back(body[i]);
  const Pose3 T = node->pose();
  const Mat3 R = T.linear();
  const Vec3 p = T.translation();
  PlaneExtractionOptions po = options_.planes;
  po.up = R.transpose() * (-gravity_W_).normalized();  // a loop correction may have tilted the world
  const double cos_match = std::cos(options_.plane_match_angle_deg * M_PI / 180.0);
  std::vector<const PlaneLandmark*> used;
  for (const ExtractedPlane& e : extractPlanes(cloud, po)) {
    if (options_.planar_ground_only && !e.ground) continue;
    // the observation in the world, the sensor on its positive side
    Plane w;
    w.normal = R * e.plane.normal;
    w.offset = e.plane.offset - w.normal.dot(p);
    const Vec3 centroid = T * e.centroid;
    PlaneLandmark* best = nullptr;
    double best_distance = options_.plane_match_distance;
    for (auto& l : landmarks_) {
      if (std::find(used.begin(), used.end(), l.get()) != used.end()) continue;
      const Plane lp = l->seenFrom();
      if (lp.normal.dot(w.normal) < cos_match) continue;
      const double d = std::abs(lp.distance(centroid));
      if (d < best_distance) best_distance = d, best = l.get();
    }
    if (!best) {
      auto l = std::make_unique<PlaneLandmark>();
      l->anchor = p;
      const Vec3 c = -w.distance(p) * w.normal;  // from the anchor to the plane's closest point
      std::copy(c.data(), c.data() + 3, l->c);
      landmarks_.push_back(std::move(l));
      best = landmarks_.back().get();
    }
    used.push_back(best);
    ++best->observers;
    Node::PlaneObservation o{best,
                             e.plane.normal,
                             e.plane.offset,
                             options_.plane_sigma_angle_deg * M_PI / 180.0,
                             std::max(options_.plane_sigma_distance, e.quality),
                             nullptr};
    o.remake();
    node->planes.push_back(std::move(o));
    ++res->planes;
    res->ground_planes += e.ground;
  }
}

void LioGraphEstimator::optimize() {
  ceres::Problem problem(nonOwningProblemOptions());
  static RightQuaternionManifold manifold;
  for (auto& n : window_) {
    problem.AddParameterBlock(n->q, 4, &manifold);
    for (double* b : {n->p, n->v, n->bg, n->ba}) problem.AddParameterBlock(b, 3);
  }
  for (auto& l : landmarks_) problem.AddParameterBlock(l->c, 3);
  if (prior_factor_) problem.AddResidualBlock(prior_factor_.get(), nullptr, prior_->blocks);
  for (size_t k = 0; k < window_.size(); ++k) {
    Node& n = *window_[k];
    for (auto& u : n.priors) problem.AddResidualBlock(u.cost.get(), nullptr, u.blocks);
    if (n.lidar) problem.AddResidualBlock(n.lidar.get(), nullptr, n.q, n.p);
    for (auto& o : n.planes) problem.AddResidualBlock(o.cost.get(), nullptr, n.q, n.p, o.landmark->c);
    if (k == 0) continue;
    Node& m = *window_[k - 1];
    if (n.imu) problem.AddResidualBlock(n.imu.get(), nullptr, imuFactorBlocks(m.inertial(), n.inertial()));
    if (n.bias_walk) problem.AddResidualBlock(n.bias_walk.get(), nullptr, biasWalkBlocks(m.inertial(), n.inertial()));
    if (n.wheel) problem.AddResidualBlock(n.wheel.get(), n.wheel_loss.get(), wheelBlocks(m, n));
    if (n.visual) problem.AddResidualBlock(n.visual.get(), n.visual_loss.get(), visualBlocks(m, n));
  }
  solveWindow(&problem, options_.solver_iterations);
}

void LioGraphEstimator::marginalizeOldest() {
  Node& a = *window_[0];
  Node& b = *window_[1];
  Marginalizer m;
  for (auto& n : window_) m.setQuaternion(n->q);
  if (prior_factor_) m.addFactor(prior_factor_.get(), prior_->blocks);
  for (auto& u : a.priors) m.addFactor(u.cost.get(), u.blocks);
  if (a.lidar) m.addFactor(a.lidar.get(), {a.q, a.p});
  std::set<const double*> drop =
      addOldestInertialFactors(&m, a.inertial(), b.inertial(), b.imu.get(), b.bias_walk.get());
  if (b.wheel) m.addFactor(b.wheel.get(), wheelBlocks(a, b), b.wheel_loss.get());
  if (b.visual) m.addFactor(b.visual.get(), visualBlocks(a, b), b.visual_loss.get());
  for (auto& o : a.planes) {
    m.addFactor(o.cost.get(), {a.q, a.p, o.landmark->c});
    if (--o.landmark->observers == 0) drop.insert(o.landmark->c);  // seen by no state that stays
  }
  prior_ = m.marginalize(drop);
  prior_factor_ = prior_ ? std::make_unique<MarginalPriorFactor>(prior_) : nullptr;
  b.imu.reset();
  b.imu_preintegration.reset();
  b.bias_walk.reset();
  b.wheel.reset();
  b.wheel_loss.reset();
  b.visual.reset();
  b.visual_loss.reset();
  for (StoredKeyframe& k : keyframes_)
    if (k.node == &a) k.node = nullptr;
  window_.pop_front();
  landmarks_.erase(std::remove_if(landmarks_.begin(), landmarks_.end(),
                                  [](const std::unique_ptr<PlaneLandmark>& l) { return l->observers == 0; }),
                   landmarks_.end());
}

Mat6 LioGraphEstimator::visualInformation(const Pose3& T_i_j) const {
  const double sr = options_.visual_sigma_rotation_deg * M_PI / 180.0;
  const double st =
      options_.visual_sigma_translation + options_.visual_sigma_translation_ratio * T_i_j.translation().norm();
  Vec6 d;
  d << Vec3::Constant(1.0 / (sr * sr)), Vec3::Constant(1.0 / (st * st));
  return d.asDiagonal();
}

std::vector<double*> LioGraphEstimator::visualBlocks(Node& a, Node& b) {
  if (estimatesVisualScale()) return {a.q, a.p, b.q, b.p, visual_scale_};
  return {a.q, a.p, b.q, b.p};
}

std::vector<double*> LioGraphEstimator::wheelBlocks(Node& a, Node& b) {
  std::vector<double*> blocks = {a.q, a.p, b.q, b.p};  // in makeWheelFactor's order
  if (estimatesWheelScale()) blocks.push_back(wheel_scale_);
  if (estimatesWheelMounting()) blocks.push_back(wheel_mounting_);
  return blocks;
}

void LioGraphEstimator::updateKeyframePoses() {
  // keyframes whose state is still in the window follow its optimisation (the local map follows at
  // the next keyframe); older ones keep the pose they left the window with
  for (StoredKeyframe& k : keyframes_)
    if (k.node) k.kf.pose = k.node->pose();
}

std::vector<size_t> LioGraphEstimator::firstKeyframePerCell(const std::vector<size_t>& candidates) const {
  if (!(options_.local_map_spacing > 0.0)) return {};
  std::vector<Vec3> positions;
  for (size_t i : candidates) positions.push_back(keyframes_[i].kf.pose.translation());
  std::vector<size_t> first;
  for (size_t j : firstPointPerVoxel(positions, options_.local_map_spacing)) first.push_back(candidates[j]);
  return first;
}

std::vector<const LioGraphEstimator::StoredKeyframe*> LioGraphEstimator::localMapKeyframes(const Vec3& here) const {
  const size_t first_newest =
      keyframes_.size() - std::min(keyframes_.size(), static_cast<size_t>(options_.local_map_keyframes));
  const double r2 = options_.local_map_radius * options_.local_map_radius;
  std::vector<size_t> older, newest;
  for (size_t i = 0; i < keyframes_.size(); ++i)
    if ((keyframes_[i].kf.pose.translation() - here).squaredNorm() <= r2)
      (i < first_newest ? older : newest).push_back(i);
  std::vector<const StoredKeyframe*> chosen;  // oldest first
  for (size_t i : firstKeyframePerCell(older)) chosen.push_back(&keyframes_[i]);
  for (size_t i : newest) chosen.push_back(&keyframes_[i]);
  return chosen;
}

void LioGraphEstimator::pruneStoredKeyframes() {
  // keep what localMapKeyframes() can still choose: the newest, and the oldest of each cell
  const size_t first_newest =
      keyframes_.size() - std::min(keyframes_.size(), static_cast<size_t>(options_.local_map_keyframes));
  std::vector<size_t> older(first_newest);
  for (size_t i = 0; i < first_newest; ++i) older[i] = i;
  std::vector<size_t> keep = firstKeyframePerCell(older);
  for (size_t i = first_newest; i < keyframes_.size(); ++i) keep.push_back(i);
  std::deque<StoredKeyframe> kept;
  for (size_t i : keep) kept.push_back(std::move(keyframes_[i]));
  keyframes_ = std::move(kept);
  // beyond the bound, the older keyframe farthest from the newest (first of equals) goes
  const size_t bound = std::max(options_.max_stored_keyframes, static_cast<size_t>(options_.local_map_keyframes));
  while (keyframes_.size() > bound) {
    const Vec3 here = keyframes_.back().kf.pose.translation();
    size_t farthest = 0;
    double far2 = -1.0;
    for (size_t i = 0; i + static_cast<size_t>(options_.local_map_keyframes) < keyframes_.size(); ++i) {
      const double d2 = (keyframes_[i].kf.pose.translation() - here).squaredNorm();
      if (d2 > far2) far2 = d2, farthest = i;
    }
    keyframes_.erase(keyframes_.begin() + static_cast<std::ptrdiff_t>(farthest));
  }
}

void LioGraphEstimator::rebuildLocalMap(const Vec3& here) {
  // Oldest first, so a voxel keeps an older keyframe's point: the newest sweep's rings, which the
  // next sweep's rings resemble wherever the body moves, would pull the match towards standing still.
  std::vector<Vec3> edges, surfaces;
  for (const StoredKeyframe* k : localMapKeyframes(here)) {
    for (const Vec3& e : k->edges) edges.push_back(k->kf.pose * e);
    for (const Vec3& s : k->surfaces) surfaces.push_back(k->kf.pose * s);
  }
  std::vector<Vec3> e_ds, s_ds;
  for (size_t i : firstPointPerVoxel(edges, options_.map_edge_voxel)) e_ds.push_back(edges[i]);
  for (size_t i : firstPointPerVoxel(surfaces, options_.map_surface_voxel)) s_ds.push_back(surfaces[i]);
  map_.rebuild(std::move(e_ds), std::move(s_ds));
}

WorldMotion LioGraphEstimator::motionOf(const double* block) const {
  for (const auto& n : window_) {
    if (block == n->q) return WorldMotion::kRotation;
    if (block == n->p) return WorldMotion::kPoint;
    if (block == n->v) return WorldMotion::kDirection;
    if (block == n->bg || block == n->ba) return WorldMotion::kNone;
  }
  // the wheel mounting is a body-frame rotation: a correction of the world leaves it
  if (block == wheel_scale_ || block == wheel_mounting_ || block == visual_scale_) return WorldMotion::kNone;
  for (const auto& l : landmarks_)
    if (block == l->c) return WorldMotion::kDirection;
  throw std::logic_error("the marginal prior holds a block that is neither a window state's nor a landmark's");
}

void LioGraphEstimator::applyLoopCorrection(const LoopCorrection& correction,
                                            const std::vector<KeyframePose>& corrected) {
  const Pose3 T = correctionStep(frame_, correction);
  frame_.correction_id = correction.id;
  frame_.T_C_O = correction.T_Ck_O;
  const Mat3 R = T.linear();
  // keyframes: corrected poses where given, the rigid correction elsewhere
  for (StoredKeyframe& k : keyframes_) {
    auto it = std::find_if(corrected.begin(), corrected.end(), [&](const KeyframePose& c) { return c.id == k.kf.id; });
    k.kf.pose = it != corrected.end() ? it->pose : T * k.kf.pose;
  }
  if (initialized()) {
    // The whole window moves rigidly, so every factor keeps its residual: the prior first (its
    // blocks are looked up in the window), then the states, the landmarks, and the factors that
    // hold world-frame quantities, remade from what they were made of.
    if (prior_) {
      std::vector<WorldMotion> motion;
      for (const double* b : prior_->blocks) motion.push_back(motionOf(b));
      prior_ = std::make_shared<MarginalPrior>(movedPrior(*prior_, motion, T));
      prior_factor_ = std::make_unique<MarginalPriorFactor>(prior_);
    }
    // the world gravity is the state's: it tilts with the frame (with no state yet, the
    // initialisation is gravity-aligned, as livo-lio's)
    gravity_W_ = R * gravity_W_;
    const Eigen::Quaterniond qR(R);
    for (auto& n : window_) {
      Eigen::Map<Eigen::Quaterniond> q(n->q);
      q = (qR * q).normalized();
      Eigen::Map<Vec3> p(n->p), v(n->v);
      p = Vec3(R * p + T.translation());
      v = Vec3(R * v);
    }
    for (auto& l : landmarks_) {
      l->anchor = T * l->anchor;
      Eigen::Map<Vec3> c(l->c);
      c = Vec3(R * c);
    }
    for (auto& n : window_) {
      if (n->imu_preintegration) n->imu.reset(makeImuFactor(*n->imu_preintegration, gravity_W_));
      if (n->lidar) {
        n->lidar_pose = T * n->lidar_pose;
        n->lidar_information = turnedInformation(n->lidar_information, R);
        n->lidar.reset(makePoseFactor(n->lidar_pose, n->lidar_information));
      }
      for (Node::Unary& u : n->priors) {
        if (u.kind == Node::Unary::Kind::kPose) {
          u.pose = T * u.pose;
          u.information = turnedInformation(u.information, R);
        } else if (u.kind == Node::Unary::Kind::kVelocity) {
          u.mean = R * u.mean;
        }
        u.remake();
      }
      for (Node::PlaneObservation& o : n->planes) o.remake();
    }
    keyframe_selector_.setReference(window_.back()->pose());
  }
  // the local map from the corrected keyframes around the new position
  rebuildLocalMap(initialized() ? window_.back()->pose().translation() : Vec3(T.translation()));
}

Mat6 LioGraphEstimator::newestPoseCovariance() {
  // the marginal of the newest pose from the window's information (ceres::Covariance would rebuild
  // the problem; the window is small, so the dense route is simple and exact)
  Node& n = *window_.back();
  Marginalizer m;
  for (auto& w : window_) m.setQuaternion(w->q);
  if (prior_factor_) m.addFactor(prior_factor_.get(), prior_->blocks);
  for (size_t k = 0; k < window_.size(); ++k) {
    Node& a = *window_[k];
    for (auto& u : a.priors) m.addFactor(u.cost.get(), u.blocks);
    if (a.lidar) m.addFactor(a.lidar.get(), {a.q, a.p});
    for (auto& o : a.planes) m.addFactor(o.cost.get(), {a.q, a.p, o.landmark->c});
    if (k == 0) continue;
    Node& b = *window_[k - 1];
    if (a.imu) m.addFactor(a.imu.get(), imuFactorBlocks(b.inertial(), a.inertial()));
    if (a.bias_walk) m.addFactor(a.bias_walk.get(), biasWalkBlocks(b.inertial(), a.inertial()));
    if (a.wheel) m.addFactor(a.wheel.get(), wheelBlocks(b, a), a.wheel_loss.get());
    if (a.visual) m.addFactor(a.visual.get(), visualBlocks(b, a), a.visual_loss.get());
  }
  // by a Cholesky factorisation of the rest; the eigen-decomposition (which also copes with a rank
  // deficient rest) only where that fails
  Eigen::MatrixXd marginal_info;
  Mat6 info;
  if (m.marginalInformation({n.q, n.p}, &marginal_info) && marginal_info.rows() == 6) {
    // as marginalize() has it: directions with no information (relative to the strongest) carry none
    const Eigen::SelfAdjointEigenSolver<Mat6> ei{Mat6(marginal_info)};
    const double top = std::max(ei.eigenvalues().maxCoeff(), 0.0);
    const Vec6 kept = (ei.eigenvalues().array() > 1e-12 * top && ei.eigenvalues().array() > 0.0)
                          .select(ei.eigenvalues().array(), 0.0)
                          .matrix();
    info = ei.eigenvectors() * kept.asDiagonal() * ei.eigenvectors().transpose();
  } else {
    std::set<const double*> drop;
    for (auto& w : window_)
      for (double* b : w->blocks())
        if (b != n.q && b != n.p) drop.insert(b);
    for (auto& l : landmarks_) drop.insert(l->c);
    drop.insert(wheel_scale_);
    drop.insert(wheel_mounting_);
    drop.insert(visual_scale_);
    const auto marginal = m.marginalize(drop, 1e-12);
    if (!marginal || marginal->J.cols() != 6) return Mat6::Identity();
    // blocks in first-seen order: make it [q, p]
    Eigen::MatrixXd J = marginal->J;
    if (marginal->blocks[0] != n.q) {
      Eigen::MatrixXd swapped(J.rows(), 6);
      swapped << J.rightCols(3), J.leftCols(3);
      J = swapped;
    }
    info = J.transpose() * J;
  }
  const Eigen::SelfAdjointEigenSolver<Mat6> es(info);
  const Vec6 inv = es.eigenvalues().cwiseMax(1e-9).cwiseInverse();
  return es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose();
}

}  // namespace livo::lio_graph
