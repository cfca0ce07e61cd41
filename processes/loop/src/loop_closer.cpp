#include "livo/loop/loop_closer.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "livo/loop/voxel_grid.hpp"

namespace livo::loop {

namespace {
// A covariance an edge can use: finite, symmetric to rounding, positive definite.
bool isCovariance(const Mat6& C) {
  if (!C.allFinite() || (C - C.transpose()).norm() > 1e-9 * C.norm()) return false;
  return Eigen::LLT<Mat6>(C).info() == Eigen::Success;
}
// Rotation that levels the body frame: R_rp with W_R_I = Rz(yaw) * R_rp.
Mat3 rollPitch(const Mat3& W_R_I) {
  const Vec3 x = W_R_I.col(0);
  const double yaw = std::atan2(x.y(), x.x());
  return Eigen::AngleAxisd(-yaw, Vec3::UnitZ()).toRotationMatrix() * W_R_I;
}
// The pose T turned about a horizontal axis (the least rotation) so that the world's up axis seen
// in its frame is up_in_body: the odometry's attitude to gravity, kept under a new yaw and position.
Pose3 withUpInBody(const Pose3& T, const Vec3& up_in_body) {
  Pose3 out = T;
  out.linear() =
      so3::normalize(Quat::FromTwoVectors(T.linear() * up_in_body, Vec3::UnitZ()).toRotationMatrix() * T.linear());
  return out;
}
// The cloud as float (as keyframe_t carries it): what later derivations see is what the first sees.
std::vector<Eigen::Vector3f> floatCloud(const Points& cloud) {
  std::vector<Eigen::Vector3f> out;
  out.reserve(cloud.size());
  for (const Vec3& p : cloud) out.push_back(p.cast<float>());
  return out;
}
Pose3 rotationOnly(const Mat3& R) {
  Pose3 T = Pose3::Identity();
  T.linear() = R;
  return T;
}
}  // namespace

std::string LoopCloser::problem(const KeyframeInput& input) const {
  if (!placements_.empty()) {
    const int64_t newest_id = placements_.back().id;
    if (input.id <= newest_id)
      return "keyframe id " + std::to_string(input.id) + " is not after " + std::to_string(newest_id);
    if (input.epoch < newest_.epoch)
      return "keyframe " + std::to_string(input.id) + " is of odometry epoch " + std::to_string(input.epoch) +
             ", before the newest keyframe's (" + std::to_string(newest_.epoch) + ")";
  }
  if (!published_.odometryToCorrected(input.epoch, input.correction_id))
    return "keyframe " + std::to_string(input.id) + " includes loop correction " + std::to_string(input.correction_id) +
           ", which this process did not publish for odometry epoch " + std::to_string(input.epoch);
  return "";
}

const LoopCloser::Placement& LoopCloser::placement(int64_t id) const {
  const auto it = std::lower_bound(placements_.begin(), placements_.end(), id,
                                   [](const Placement& p, int64_t i) { return p.id < i; });
  if (it == placements_.end() || it->id != id) throw std::out_of_range("unknown keyframe " + std::to_string(id));
  return *it;
}

size_t LoopCloser::odometryEdgesAcrossEpochs() const {
  size_t n = 0;
  for (const PoseEdge& e : graph_.edges()) n += !e.is_loop && nodes_.at(e.from).epoch != nodes_.at(e.to).epoch;
  return n;
}

std::vector<int64_t> LoopCloser::olderNodesNear(int64_t kf_id, const Keyframe& kf, const Vec3& p, double radius) const {
  const int64_t recent = static_cast<int64_t>(options_.candidates.exclude_recent_s * 1e6);
  std::vector<std::pair<double, int64_t>> near;
  for (const auto& [id, node] : nodes_) {
    if (id >= kf_id) break;
    if (node.epoch != kf.epoch || kf.utime - node.utime < recent) continue;
    const double d2 = (graph_.pose(id).translation() - p).squaredNorm();
    if (d2 <= radius * radius) near.push_back({d2, id});
  }
  std::sort(near.begin(), near.end());
  std::vector<int64_t> out;
  out.reserve(near.size());
  for (const auto& [d2, id] : near) out.push_back(id);
  return out;
}

std::vector<int64_t> LoopCloser::withKeypoints(const std::vector<int64_t>& nodes, int count) {
  // the nearest `count` of those with keypoints, as filtering them all first would give
  std::vector<int64_t> out;
  for (size_t i = 0; i < nodes.size() && static_cast<int>(out.size()) < count; ++i)
    if (nodeHasKeypoints(nodes[i])) out.push_back(nodes[i]);
  return out;
}

bool LoopCloser::nodeHasKeypoints(int64_t id) {
  Keyframe& node = nodes_.at(id);
  if (!node.has_keypoints) node.has_keypoints = features(id)->hasKeypoints();
  return *node.has_keypoints;
}

bool LoopCloser::Features::hasKeypoints() const {
  if (coarse_) return !coarse_->points.empty();
  if (!has_keypoints_) has_keypoints_ = anyKeypointDescribable(keypoints_, options_);
  return *has_keypoints_;
}

const CoarseFeatures& LoopCloser::Features::coarse() const {
  if (!coarse_) {
    // without keypoints there is nothing to describe (describing would find as much)
    coarse_ = has_keypoints_ && !*has_keypoints_ ? CoarseFeatures{} : describeCoarseKeypoints(keypoints_, options_);
    keypoints_ = CoarseKeypoints{};  // no longer needed, and a kd-tree and a normal per voxel
  }
  return *coarse_;
}

const GicpCloud& LoopCloser::Features::fine(const std::function<FloatCloud()>& cloud_I) const {
  if (!fine_)
    fine_ = GicpCloud::build(centroidPerVoxel(levelled(cloud_I(), G_R_I_), fine_voxel_size_), covariance_neighbors_);
  return *fine_;
}

Points LoopCloser::Features::levelled(const FloatCloud& cloud_I, const Mat3& G_R_I) {
  Points cloud;
  cloud.reserve(cloud_I.size());
  for (const Eigen::Vector3f& p : cloud_I) cloud.push_back(p.cast<double>());
  return transformed(cloud, rotationOnly(G_R_I));
}

LoopCloser::Features::Features(const FloatCloud& cloud_I, const Mat3& G_R_I, const LoopCloserOptions& options)
    : options_(options.coarse),
      G_R_I_(G_R_I),
      fine_voxel_size_(options.fine_voxel_size),
      covariance_neighbors_(options.covariance_neighbors),
      keypoints_(detectCoarseKeypoints(levelled(cloud_I, G_R_I), options.coarse)) {}

void LoopCloser::cacheFeatures(int64_t id, std::shared_ptr<const Features> f) {
  for (auto it = cache_.begin(); it != cache_.end(); ++it)
    if (it->first == id) {
      cache_.erase(it);
      break;
    }
  cache_.emplace_front(id, std::move(f));
  while (cache_.size() > static_cast<size_t>(std::max(1, options_.feature_cache_keyframes))) cache_.pop_back();
}

std::shared_ptr<const LoopCloser::Features> LoopCloser::features(int64_t id) {
  for (auto it = cache_.begin(); it != cache_.end(); ++it)
    if (it->first == id) {
      cache_.splice(cache_.begin(), cache_, it);
      return it->second;
    }
  auto f = std::make_shared<const Features>(clouds_.get(id), nodes_.at(id).G_R_I, options_);
  cacheFeatures(id, f);
  return f;
}

Points LoopCloser::mapCloud(int64_t id) const {
  Points cloud_I;
  for (const Eigen::Vector3f& p : clouds_.get(id)) cloud_I.push_back(p.cast<double>());
  Points map = centroidPerVoxel(cloud_I, options_.map_voxel_size);
  for (Vec3& p : map) p = p.cast<float>().cast<double>();  // float, as the global map has always kept them
  return map;
}

AcceptedLoop LoopCloser::acceptedLoop(int64_t from_id, const Keyframe& from, int64_t to_id, const Keyframe& to,
                                      const LoopRegistrationResult& r) const {
  AcceptedLoop loop;
  loop.from_id = from_id;
  loop.to_id = to_id;
  loop.from_utime = from.utime;
  loop.to_utime = to.utime;
  // registration works in the levelled frames G; the loop is between the body frames I
  loop.T_to_from = rotationOnly(to.G_R_I).inverse() * r.T_target_source * rotationOnly(from.G_R_I);
  loop.covariance = loopCovariance(r, from);
  loop.coarse_inliers = r.coarse.num_inliers;
  loop.fitness = r.fine.fitness;
  loop.overlap = r.fine.overlap;
  return loop;
}

Pose3 LoopCloser::pose(const Placement& k) const {
  const Pose3 T = k.node == k.id ? graph_.pose(k.id) : graph_.pose(k.node) * k.T_node_kf;
  return levelled(T, k.up_in_body);
}

Pose3 LoopCloser::levelled(const Pose3& T, const Vec3& up_in_body) const {
  // roll and pitch are the odometry's (it measures gravity); a loop registration's tilt, carried by
  // T_node_kf or by a node's estimate within its gravity prior, would tilt a consumer's state and map
  return options_.gravity_prior_sigma > 0.0 ? withUpInBody(T, up_in_body) : T;
}

Pose3 LoopCloser::pose(int64_t id) const { return pose(placement(id)); }

void LoopCloser::forEachPose(const std::function<void(int64_t, const Pose3&)>& visit) const {
  for (const Placement& k : placements_) visit(k.id, pose(k));
}

Mat6 LoopCloser::loopCovariance(const LoopRegistrationResult& r, const Keyframe& from) const {
  if (!options_.registration_information) {
    Vec6 sigma;
    sigma << Vec3::Constant(options_.loop_rotation_sigma), Vec3::Constant(options_.loop_translation_sigma);
    return sigma.cwiseAbs2().asDiagonal();
  }
  // registered between the levelled frames: T_I = Q_to^-1 T_G Q_from, so T_I Exp(xi_I) =
  // Q_to^-1 T_G Exp(xi_G) Q_from gives xi_I = Ad(Q_from^-1) xi_G (a rotation: both blocks rotated)
  const Mat6 cov_G = registrationCovariance(r.fine, r.T_target_source, options_.loop_information);
  Mat6 A = Mat6::Zero();
  A.topLeftCorner<3, 3>() = A.bottomRightCorner<3, 3>() = from.G_R_I.transpose();
  return A * cov_G * A.transpose();
}

DriftModel LoopCloser::driftModel() const {
  return {options_.odometry_rotation_floor, options_.odometry_translation_floor, options_.odometry_rotation_per_m,
          options_.odometry_translation_per_m};
}

std::optional<RefusedLoop> LoopCloser::inconsistency(const AcceptedLoop& loop, const Keyframe& from,
                                                     const Pose3& W_T_from) const {
  if (!options_.consistency_check) return std::nullopt;
  const Keyframe& to = nodes_.at(loop.to_id);
  const DriftModel drift = driftModel();
  RefusedLoop refusal;
  refusal.from_id = loop.from_id;
  refusal.to_id = loop.to_id;
  refusal.merged = loop.merged;
  refusal.T_to_from = loop.T_to_from;
  std::ostringstream why;
  // the graph's relative pose of the two, uncertain by the odometry's drift over the path between them
  const double path = std::abs(from.path - to.path);
  const Pose3 graph_T = graph_.pose(loop.to_id).inverse() * W_T_from;
  const double chi2 = poseChi2(graph_T, driftCovariance(path, drift), loop.T_to_from, loop.covariance);
  if (chi2 > options_.consistency_chi2) {
    refusal.against = "odometry";
    refusal.chi2 = chi2;
    refusal.path = path;
    why << "inconsistent with the odometry: chi2 " << chi2 << " > " << options_.consistency_chi2 << " over " << path
        << " m (" << (graph_T.inverse() * loop.T_to_from).translation().norm() << " m apart)";
    refusal.reason = why.str();
    return refusal;
  }
  // the cycle through the earlier loop with the least odometry on either side (C <- D), if any has
  // less than the path above: T_to_from = odo(to -> C) T_C_D odo(D -> from)
  long best = -1;
  double best_path = path, best_1 = 0.0, best_3 = 0.0;
  for (size_t k = 0; k < loops_.size(); ++k) {
    if (anchors_[k].epoch != from.epoch) continue;
    const double l1 = std::abs(to.path - nodes_.at(loops_[k].to_id).path);
    const double l3 = std::abs(anchors_[k].from_path - from.path);
    if (l1 + l3 < best_path) {
      best = static_cast<long>(k);
      best_path = l1 + l3;
      best_1 = l1;
      best_3 = l3;
    }
  }
  if (best < 0) return std::nullopt;
  const AcceptedLoop& earlier = loops_[best];
  const Pose3 T1 = to.odometry.inverse() * nodes_.at(earlier.to_id).odometry;
  const Pose3 T3 = anchors_[best].from_odometry.inverse() * from.odometry;
  const Mat6 cov12 = composedCovariance(driftCovariance(best_1, drift), earlier.T_to_from, earlier.covariance);
  const Mat6 cov = composedCovariance(cov12, T3, driftCovariance(best_3, drift));
  const double cycle_chi2 = poseChi2(T1 * earlier.T_to_from * T3, cov, loop.T_to_from, loop.covariance);
  if (cycle_chi2 <= options_.consistency_chi2) return std::nullopt;
  refusal.against = "loop";
  refusal.against_from_id = earlier.from_id;
  refusal.against_to_id = earlier.to_id;
  refusal.chi2 = cycle_chi2;
  refusal.path = best_path;
  why << "inconsistent with loop " << earlier.from_id << " -> " << earlier.to_id << ": chi2 " << cycle_chi2 << " > "
      << options_.consistency_chi2 << " over a cycle with " << best_path << " m of odometry";
  refusal.reason = why.str();
  return refusal;
}

void LoopCloser::accept(const AcceptedLoop& loop, const Keyframe& from, AddResult& result) {
  loops_.push_back(loop);
  anchors_.push_back(LoopAnchor{from.epoch, from.odometry, from.path});
  result.loop = loop;
  keyframes_since_loop_ = 0;
}

void LoopCloser::noteAttempt(const LoopRegistrationResult& r, AddResult& result) {
  ++registrations_;
  if (!r.accepted) rejected_registrations_.add(r.rejected_by.empty() ? r.reason : r.rejected_by);
  result.attempts.push_back(r);
}

LoopRegistrationResult LoopCloser::registerPair(int64_t from_id, const Features& from, const FloatCloud& from_cloud,
                                                int64_t to_id, const Features& to) const {
  LoopRegistrationResult r = registerLoop(
      from.coarse(), to.coarse(), [&]() -> const GicpCloud& { return from.fine([&] { return from_cloud; }); },
      [&]() -> const GicpCloud& { return to.fine([&] { return clouds_.get(to_id); }); }, options_.registration);
  if (options_.registration_hook) options_.registration_hook(from_id, to_id, r);
  return r;
}

Mat6 LoopCloser::chainOdometryCovariance(const Keyframe& to) const {
  if (options_.odometry_covariance_from_filter && chain_.filter_covariance) return chain_.odometry_covariance;
  return chainDriftInformation(to).inverse();
}

Mat6 LoopCloser::chainDriftInformation(const Keyframe& to) const {
  // the increment's covariance from the absolute ones, floored by the drift model over the path
  return relativeInformation(
      chain_.start_keyframe.covariance, to.covariance,
      std::hypot(options_.odometry_rotation_floor, options_.odometry_rotation_per_m * chain_.path),
      std::hypot(options_.odometry_translation_floor, options_.odometry_translation_per_m * chain_.path));
}

std::optional<Mat6> LoopCloser::odometryBetween(const Keyframe& a, const Keyframe& b) const {
  const Keyframe& early = a.path <= b.path ? a : b;
  const Keyframe& late = a.path <= b.path ? b : a;
  if (!options_.odometry_covariance_from_filter || !early.cumulative_from_filter || !late.cumulative_from_filter ||
      a.epoch != b.epoch)
    return std::nullopt;
  // the left perturbation of the later pose given the earlier one, then as the right one of T_a^-1 T_b
  const Mat6 D = late.cumulative_covariance - early.cumulative_covariance;
  const Mat6 A = se3::adjoint(b.odometry.inverse());
  const Mat6 cov = A * D * A.transpose();
  return 0.5 * (cov + cov.transpose());
}

Mat6 LoopCloser::chainCovariance(const Keyframe& to) const {
  // the odometry part, then the loop part (if the chain starts with one) adds its covariance
  // (carried to the end of the chain)
  const Mat6 odometry = chainOdometryCovariance(to);
  if (!chain_.via_loop) return odometry;
  // T_node_to = T_node_start (the loop) * the odometry increment from start to `to`
  return composedCovariance(chain_.loop_covariance, chain_.start_keyframe.odometry.inverse() * to.odometry, odometry);
}

std::optional<Correction> LoopCloser::addLoopEdge(const PoseEdge* edge, int64_t current, const Keyframe& cur,
                                                  AcceptedLoop* loop) {
  // where the loop puts the keyframe (the joined or loop node's pose and the measured offset)
  // against where the odometry has it now (in the newest correction it was sent)
  const Pose3 implied = levelled(graph_.pose(loop->to_id) * loop->T_to_from, upInBody(cur));
  const Pose3 odometry = *published_.odometryToCorrected(cur.epoch, published_.newest(cur.epoch)) * cur.odometry;
  const Pose3 discrepancy = implied.inverse() * odometry;
  loop->residual_rotation = so3::Log(Mat3(discrepancy.linear())).norm();
  loop->residual_translation = discrepancy.translation().norm();
  // the discrepancy against what the odometry between the two keyframes and the loop allow
  // (only with the odometry's own covariance: the drift model is loose by design, to refuse only
  // what no drift explains)
  const std::optional<Mat6> between = odometryBetween(nodes_.at(loop->to_id), cur);
  if (between) {
    loop->odometry_covariance = *between;
    loop->correction_chi2 =
        poseChi2(graph_.pose(loop->to_id).inverse() * odometry, *between, loop->T_to_from, loop->covariance);
  }
  const bool resolved = loop->residual_translation >= options_.min_correction_translation ||
                        loop->residual_rotation >= options_.min_correction_rotation;
  const bool significant =
      !between || options_.correction_chi2 <= 0.0 || loop->correction_chi2 > options_.correction_chi2;
  loop->corrected = resolved && significant;
  if (edge) {
    graph_.addEdge(*edge);
    ++loops_since_optimization_;
  }
  if (!loop->corrected) return std::nullopt;
  graph_.optimize();
  loops_since_optimization_ = 0;
  if (options_.correction_from_optimum) {
    // what the optimum changes for the consumers: the keyframe's pose against theirs
    const Pose3 shift = odometry.inverse() * pose(current);
    loop->optimum_shift_rotation = so3::Log(Mat3(shift.linear())).norm();
    loop->optimum_shift_translation = shift.translation().norm();
    loop->corrected = loop->optimum_shift_translation >= options_.min_correction_translation ||
                      loop->optimum_shift_rotation >= options_.min_correction_rotation;
    if (!loop->corrected) return std::nullopt;
  }
  // The odometry adopts T_Ck_O = corrected * raw^-1 of this keyframe (the whole epoch's raw frame
  // onto the optimised one); T_Ck_Cj is what it applies if it is in the previous correction j.
  Correction c;
  c.id = next_correction_id_++;
  c.epoch = cur.epoch;
  c.previous_id = published_.newest(cur.epoch);
  c.T_Ck_O = pose(current) * cur.odometry.inverse();
  c.T_Ck_Cj = c.T_Ck_O * published_.odometryToCorrected(cur.epoch, c.previous_id)->inverse();
  published_.add(c.id, c.epoch, c.T_Ck_O);
  return c;
}

std::optional<Mat6> LoopCloser::accumulateIncrement(const KeyframeInput& input, const Pose3& step, Keyframe* kf) {
  // the odometry's covariance of the increment, if it came with one from the previous keyframe
  // (without its held-calibration part unless compose_held_calibration; whole if that part leaves
  // no covariance, rather than none and the drift model)
  const Mat6 filter_part = input.relative_covariance - input.relative_covariance_held_calibration;
  const bool whole = options_.compose_held_calibration || !isCovariance(filter_part);
  const Mat6& increment = whole ? input.relative_covariance : filter_part;
  std::optional<Mat6> given;
  if (options_.odometry_covariance_from_filter && input.relative_to_id == newest_.id && isCovariance(increment)) {
    given = options_.odometry_covariance_scale * increment;
    unusable_held_parts_ += whole && !options_.compose_held_calibration;
  }
  const Mat6 cov = given ? *given : driftCovariance(step.translation().norm(), driftModel());
  const Mat6 Ad = se3::adjoint(kf->odometry);
  const Mat6 W = newest_.cumulative_covariance + Ad * cov * Ad.transpose();
  kf->cumulative_covariance = 0.5 * (W + W.transpose());
  kf->cumulative_from_filter = newest_.cumulative_from_filter && given.has_value();
  return given;
}

bool LoopCloser::optimizePendingLoops() {
  if (loops_since_optimization_ == 0) return false;
  graph_.optimize();
  loops_since_optimization_ = 0;
  return true;
}

void LoopCloser::addNode(int64_t id, const Keyframe& kf, const Pose3& estimate, const FloatCloud& cloud) {
  graph_.addNode(id, estimate);
  if (options_.gravity_prior_sigma > 0.0) graph_.addGravityPrior(id, upInBody(kf), options_.gravity_prior_sigma);
  nodes_.emplace(id, kf);
  clouds_.put(id, cloud);
  placements_.push_back(Placement{id, kf.utime, kf.epoch, id, Pose3::Identity(), upInBody(kf)});
}

LoopCloser::Keyframe LoopCloser::arrivingKeyframe(const KeyframeInput& input) const {
  Keyframe kf;
  kf.id = input.id;
  kf.utime = input.utime;
  kf.epoch = input.epoch;
  kf.odometry = published_.odometryToCorrected(input.epoch, input.correction_id)->inverse() * input.pose;
  kf.covariance = input.covariance.allFinite() ? input.covariance : Mat6::Zero();
  kf.G_R_I = rollPitch(input.pose.linear());
  return kf;
}

LoopCloser::Chain LoopCloser::chainFrom(const Keyframe& node) {
  return Chain{node.id, node.id, node, Pose3::Identity(), false, 0.0, Mat6::Zero()};
}

bool LoopCloser::hasKeypoints(Arrival& cur) {
  if (!cur.features) cur.features = std::make_shared<const Features>(cur.cloud, cur.kf.G_R_I, options_);
  cur.kf.has_keypoints = cur.features->hasKeypoints();
  if (const auto node = nodes_.find(cur.kf.id); node != nodes_.end()) node->second.has_keypoints = cur.kf.has_keypoints;
  return *cur.kf.has_keypoints;
}

void LoopCloser::extendChain(const Pose3& step, const std::optional<Mat6>& step_covariance) {
  chain_.path += step.translation().norm();
  if (step_covariance)
    chain_.odometry_covariance = composedCovariance(chain_.odometry_covariance, step, *step_covariance);
  else
    chain_.filter_covariance = false;
}

std::optional<int64_t> LoopCloser::nodeToJoin(Arrival& cur, const Pose3& estimate) {
  if (options_.merge_distance <= 0) return std::nullopt;
  const std::vector<int64_t> reach = olderNodesNear(cur.kf.id, cur.kf, estimate.translation(), options_.merge_distance);
  if (reach.empty() || !hasKeypoints(cur)) return std::nullopt;
  const std::vector<int64_t> with = withKeypoints(reach, 1);
  if (with.empty()) return std::nullopt;
  return with.front();
}

std::optional<AcceptedLoop> LoopCloser::verifiedLoop(const Arrival& cur, int64_t to_id, bool merged,
                                                     const Pose3& W_T_from, AddResult& result) {
  const Keyframe& target = nodes_.at(to_id);
  const std::shared_ptr<const Features> target_features = features(to_id);
  const LoopRegistrationResult r = registerPair(cur.kf.id, *cur.features, cur.cloud, to_id, *target_features);
  noteAttempt(r, result);
  if (!r.accepted) return std::nullopt;
  AcceptedLoop loop = acceptedLoop(cur.kf.id, cur.kf, to_id, target, r);
  loop.merged = merged;
  if (std::optional<RefusedLoop> refusal = inconsistency(loop, cur.kf, W_T_from)) {
    refused_.push_back(*refusal);
    result.refused.push_back(*refusal);
    return std::nullopt;
  }
  return loop;
}

void LoopCloser::joinNode(const Arrival& cur, int64_t node, const Pose3& T_chain_kf, AcceptedLoop loop,
                          AddResult& result) {
  const Keyframe& kf = cur.kf;
  placements_.push_back(Placement{kf.id, kf.utime, kf.epoch, node, loop.T_to_from, upInBody(kf)});
  PoseEdge e;  // none if the chain's node is the joined one (no new relation)
  e.from = chain_.node;
  e.to = node;
  e.T_from_to = T_chain_kf * loop.T_to_from.inverse();
  e.is_loop = true;
  const Mat6 cov = composedCovariance(chainCovariance(kf), loop.T_to_from.inverse(),
                                      inverseCovariance(loop.T_to_from, loop.covariance));
  e.information = informationFromCovariance(edgeCovarianceFromRight(e.T_from_to, cov));
  result.correction = addLoopEdge(node != chain_.node ? &e : nullptr, kf.id, kf, &loop);
  accept(loop, kf, result);
  chain_ = Chain{node, kf.id, kf, loop.T_to_from, true, 0.0, loop.covariance};
}

void LoopCloser::addChainNode(const Arrival& cur, const Pose3& T_node_kf, const Pose3& estimate) {
  const Keyframe& kf = cur.kf;
  PoseEdge e;
  e.from = chain_.node;
  e.to = kf.id;
  e.T_from_to = T_node_kf;
  e.is_loop = chain_.via_loop;  // with a loop part it is no raw odometry increment
  const bool from_filter = options_.odometry_covariance_from_filter && chain_.filter_covariance;
  e.information = chain_.via_loop || from_filter
                      ? informationFromCovariance(edgeCovarianceFromRight(T_node_kf, chainCovariance(kf)))
                      : chainDriftInformation(kf);
  addNode(kf.id, kf, estimate, cur.cloud);
  graph_.addEdge(e);
  chain_ = chainFrom(kf);
}

bool LoopCloser::placeOnChain(Arrival& cur, AddResult& result) {
  const Keyframe& kf = cur.kf;
  // the odometry's estimate: the chain's node, its loop part, the raw odometry since its start
  const Pose3 T_node_kf = chain_.T_node_start * (chain_.start_keyframe.odometry.inverse() * kf.odometry);
  const Pose3 estimate = levelled(graph_.pose(chain_.node) * T_node_kf, upInBody(kf));
  const int64_t recent = static_cast<int64_t>(options_.candidates.exclude_recent_s * 1e6);
  const bool older_node = kf.utime - nodes_.at(chain_.node).utime >= recent;
  if (options_.merge_distance > 0 && older_node && T_node_kf.translation().norm() <= options_.merge_distance) {
    // passing again near the older node the odometry hangs from: the keyframe joins it (its
    // cloud and features are not needed: the node represents it)
    placements_.push_back(Placement{kf.id, kf.utime, kf.epoch, chain_.node, T_node_kf, upInBody(kf)});
    return false;
  }
  if (const std::optional<int64_t> near = nodeToJoin(cur, estimate)) {
    // the keyframe joins the older node if it registers to it (else it becomes a node of its own)
    if (std::optional<AcceptedLoop> loop = verifiedLoop(cur, *near, true, estimate, result)) {
      joinNode(cur, *near, T_node_kf, *loop, result);
      return false;
    }
  }
  addChainNode(cur, T_node_kf, estimate);
  return result.attempts.empty();  // the nearest older node did not register: no second try
}

void LoopCloser::searchLoops(Arrival& cur, AddResult& result) {
  // graph nodes only (a keyframe that joined one is represented by it), nearest first
  std::vector<int64_t> candidates;
  const std::vector<int64_t> near =
      olderNodesNear(cur.kf.id, cur.kf, graph_.pose(cur.kf.id).translation(), options_.candidates.search_radius);
  if (!near.empty() && options_.candidates.max_candidates > 0 && hasKeypoints(cur))
    candidates = withKeypoints(near, options_.candidates.max_candidates);
  if (cur.features) cacheFeatures(cur.kf.id, cur.features);
  for (int64_t cand : candidates) {
    std::optional<AcceptedLoop> loop = verifiedLoop(cur, cand, false, graph_.pose(cur.kf.id), result);
    if (!loop) continue;
    PoseEdge e;
    e.from = cand;
    e.to = cur.kf.id;
    e.T_from_to = loop->T_to_from;
    e.is_loop = true;
    e.information = informationFromCovariance(edgeCovarianceFromRight(loop->T_to_from, loop->covariance));
    result.correction = addLoopEdge(&e, cur.kf.id, cur.kf, &*loop);
    accept(*loop, cur.kf, result);
    break;
  }
}

AddResult LoopCloser::addKeyframe(const KeyframeInput& input) {
  if (const std::string why = problem(input); !why.empty()) throw std::invalid_argument(why);
  Arrival cur{arrivingKeyframe(input), floatCloud(input.cloud), nullptr};
  const bool cooling = ++keyframes_since_loop_ <= options_.candidates.cooldown_keyframes;
  const bool first_of_epoch = placements_.empty() || newest_.epoch != input.epoch;
  const Pose3 step = newest_.odometry.inverse() * cur.kf.odometry;  // the increment from the previous keyframe
  cur.kf.path = first_of_epoch ? 0.0 : newest_.path + step.translation().norm();
  const std::optional<Mat6> step_covariance = first_of_epoch ? std::nullopt : accumulateIncrement(input, step, &cur.kf);
  newest_ = cur.kf;  // what the next keyframe's odometry step starts from (has_keypoints is not used)

  AddResult result;
  if (first_of_epoch) {
    // the first keyframe, or the first of a new epoch: a segment of its own, in its raw pose
    // (0 = the raw frame for the graph's first node, which PoseGraph holds fixed anyway)
    const bool first = placements_.empty();
    addNode(input.id, cur.kf, cur.kf.odometry, cur.cloud);
    if (!first) graph_.holdFixed(input.id);
    chain_ = chainFrom(cur.kf);
  } else {
    extendChain(step, step_covariance);
    if (!placeOnChain(cur, result)) return result;
  }
  if (!cooling) searchLoops(cur, result);
  return result;
}

}  // namespace livo::loop
