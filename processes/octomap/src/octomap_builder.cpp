#include "livo/octomap/octomap_builder.hpp"

#include <algorithm>
#include <cmath>

namespace livo::octomap {

OctomapBuilder::OctomapBuilder(const OctomapOptions& options, const Pose3& T_I_L)
    : options_(options), T_I_L_(T_I_L), map_(options), clouds_(options.keyframe_step) {}

bool OctomapBuilder::addScan(const RegisteredScanView& scan, std::string* error) {
  if (have_previous_ && scan.utime <= previous_utime_) {
    *error = "scan stamp not after the previous scan";
    return false;
  }
  if (!scan.T_W_I.matrix().allFinite()) {
    *error = "scan pose is not finite";
    return false;
  }
  // the previous sweep's end pose is this sweep's start pose if the sweeps are contiguous
  const int64_t span = std::max<int64_t>(1, scan.utime - scan.cloud_utime);
  const bool interpolate = have_previous_ && std::llabs(previous_utime_ - scan.cloud_utime) <= span / 2 + 1000;
  const int segments = interpolate ? std::max(1, options_.origin_segments) : 1;
  std::vector<std::vector<Eigen::Vector3f>> slices(segments);
  for (int j = 0; j < scan.num_points; ++j) {
    const Eigen::Vector3f p(scan.x[j], scan.y[j], scan.z[j]);
    if (!p.allFinite()) continue;
    int s = segments - 1;
    if (segments > 1 && scan.time_offset && std::isfinite(scan.time_offset[j])) {
      const double a =
          (scan.cloud_utime + scan.time_offset[j] * 1e6 - previous_utime_) / double(scan.utime - previous_utime_);
      s = std::clamp(static_cast<int>(a * segments), 0, segments - 1);
    }
    slices[s].push_back(p);
  }
  std::vector<OccupancyMap::Slice> cast;
  for (int s = 0; s < segments; ++s) {
    if (slices[s].empty()) continue;
    const Pose3 T = segments > 1 ? se3::interpolate(previous_pose_, scan.T_W_I, (s + 0.5) / segments) : scan.T_W_I;
    OccupancyMap::Slice slice;
    slice.origin = (T * T_I_L_).translation();
    slice.points = &slices[s];
    cast.push_back(slice);
  }
  map_.setTime(scan.utime);
  map_.insertSweep(cast);
  map_.evictIdle();
  if (staged_) {
    // the sweep goes into the tree being rebuilt too (its tiles then stay in memory until the
    // rebuild's own clock, the keyframes' times, passes it), then the next keyframes
    staged_->map->setTime(scan.utime);
    staged_->map->insertSweep(cast);
    stepStagedRebuild(options_.rebuild_keyframes_per_scan);
  }
  have_previous_ = true;
  previous_utime_ = scan.utime;
  previous_pose_ = scan.T_W_I;
  ++scans_;
  return true;
}

bool OctomapBuilder::addKeyframe(int64_t id, Keyframe keyframe) {
  if (!keyframe.T_W_I.matrix().allFinite()) return false;
  if (options_.keyframe_spacing > 0 && !keyframes_.count(id)) {
    const double d2 = options_.keyframe_spacing * options_.keyframe_spacing;
    for (const auto& [other, k] : keyframes_)
      if ((k.T_W_I.translation() - keyframe.T_W_I.translation()).squaredNorm() < d2) {
        ++not_kept_;  // its sweep is in the map; a rebuild takes the kept one near it
        return true;
      }
  }
  StoredKeyframe& k = keyframes_[id];
  // the keyframe's sweep went into the tree (as a registered scan) at the keyframe's pose
  k.in_tree = keyframe.T_W_I;
  k.reach = T_I_L_.translation().norm();
  for (const Eigen::Vector3f& p : keyframe.points) k.reach = std::max(k.reach, double(p.norm()));
  k.utime = keyframe.utime;
  k.T_W_I = keyframe.T_W_I;
  clouds_.put(id, keyframe.points);
  return true;
}

int OctomapBuilder::applyCorrection(const std::map<int64_t, Pose3>& corrected, const Pose3& unlisted) {
  int moved = 0;
  for (auto& [id, k] : keyframes_) {
    auto it = corrected.find(id);
    const Pose3 pose = it != corrected.end() ? it->second : unlisted * k.T_W_I;
    if (!pose.matrix().allFinite()) continue;
    if ((pose.matrix() - k.T_W_I.matrix()).cwiseAbs().maxCoeff() < 1e-12) continue;
    k.T_W_I = pose;
    ++moved;
  }
  last_shift_ = maxShift();
  last_rebuilt_ = moved > 0 && last_shift_ > options_.rebuild_tolerance;
  // a staged rebuild under way goes on (the keyframes it has cast are within the tolerance or are
  // taken up by the next rebuild, when it ends); else the map is rebuilt at once or staged
  if (last_rebuilt_ && staged_) last_rebuilt_ = false;
  if (last_rebuilt_) {
    if (options_.rebuild_keyframes_per_scan > 0)
      startStagedRebuild();
    else
      rebuild();
  }
  // the next scan comes in the corrected frame: do not interpolate across the jump
  have_previous_ = false;
  return moved;
}

double OctomapBuilder::maxShift() const {
  // how far the tree's contents are from the corrected keyframes: a point p of the body frame
  // moves by |(R1 - R0) p + t1 - t0| <= |t1 - t0| + 2 sin(angle / 2) |p|
  double shift = 0.0;
  for (const auto& [id, k] : keyframes_) {
    const Pose3& a = k.in_tree;
    const Pose3& b = k.T_W_I;
    const double angle = so3::Log(Mat3(a.linear().transpose() * b.linear())).norm();
    shift = std::max(shift, (b.translation() - a.translation()).norm() + 2.0 * std::sin(0.5 * angle) * k.reach);
  }
  return shift;
}

void OctomapBuilder::castKeyframe(int64_t id, StoredKeyframe* kf, OccupancyMap* map) {
  const std::vector<Eigen::Vector3f> points = clouds_.get(id);
  std::vector<Eigen::Vector3f> world;
  world.reserve(points.size());
  for (const Eigen::Vector3f& p : points) world.push_back((kf->T_W_I * p.cast<double>()).cast<float>());
  // in time order, as the sweeps came: tiles the rebuild has passed go to disk as they did then
  map->setTime(kf->utime);
  map->insertRays(world, (kf->T_W_I * T_I_L_).translation());
  map->evictIdle();
  kf->in_tree = kf->T_W_I;
}

void OctomapBuilder::rebuild() {
  map_.clear();
  for (auto& [id, kf] : keyframes_) castKeyframe(id, &kf, &map_);
  ++rebuilds_;
}

void OctomapBuilder::startStagedRebuild() {
  staged_ = std::make_unique<StagedRebuild>();
  staged_->map = std::make_unique<OccupancyMap>(options_);
  for (const auto& [id, kf] : keyframes_) staged_->pending.push_back(id);
}

void OctomapBuilder::stepStagedRebuild(int keyframes) {
  for (int i = 0; i < keyframes && staged_->next < staged_->pending.size(); ++i, ++staged_->next) {
    const int64_t id = staged_->pending[staged_->next];
    auto it = keyframes_.find(id);
    if (it != keyframes_.end()) castKeyframe(id, &it->second, staged_->map.get());
  }
  if (staged_->next < staged_->pending.size()) return;
  map_ = std::move(*staged_->map);
  staged_.reset();
  staged_finished_ = true;
  ++rebuilds_;
  // corrections that came while it ran and moved a keyframe it had cast: the next rebuild
  if (maxShift() > options_.rebuild_tolerance) startStagedRebuild();
}

void OctomapBuilder::finishRebuild() {
  // one pass at most: a rebuild that ends stale starts another, which is then done at once
  if (staged_) stepStagedRebuild(static_cast<int>(staged_->pending.size()));
  if (staged_) stepStagedRebuild(static_cast<int>(staged_->pending.size()));
}

}  // namespace livo::octomap
