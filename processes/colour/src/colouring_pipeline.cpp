#include "livo/colour/colouring_pipeline.hpp"

#include <algorithm>
#include <cmath>

#include "livo/colour/exposure_gain.hpp"

namespace livo::colour {

namespace {
// How often the points no image can colour any more leave the map (sensor time): one pass over the
// resident points each time, so not per scan; in between they are at most this much older.
constexpr int64_t kPrunePeriodUs = 1000000;

DepthBufferOptions depthOptions(const ColourOptions& o) {
  DepthBufferOptions d;
  d.cell_px = o.depth_cell_px;
  d.occluder_radius = o.occluder_radius;
  d.max_splat_cells = o.max_splat_cells;
  d.tolerance = o.depth_tolerance;
  d.tolerance_rel = o.depth_tolerance_rel;
  return d;
}
}  // namespace

ColouringPipeline::ColouringPipeline(const ColourOptions& options, const CameraRig& camera)
    : options_(options),
      camera_(camera),
      depth_(camera.width, camera.height, std::max(camera.fx, camera.fy), depthOptions(options)),
      map_(options.voxel_size,
           // a tile stays while the scans an image may still need (2 windows + 1 s) can touch it
           TileOptions{
               options.tile_size,
               options.tile_idle_s > 0 ? std::max(options.tile_idle_s, 2 * options.max_time_difference + 2.0) : 0.0, "",
               static_cast<size_t>(std::max(0, options.max_resident_points)), 2 * options.max_time_difference + 2.0}),
      reference_exposure_(options.reference_exposure_s) {
  // the camera's field: its axis to the farthest ray through the image border
  const CameraRig& rig = camera_.rig();
  double widest = 0.0;
  auto look = [&](double u, double v) {
    const Eigen::Vector3d ray = camera_.pixelRay(Eigen::Vector2d(u, v));
    if (ray.allFinite()) widest = std::max(widest, std::atan2(ray.head<2>().norm(), ray.z()));
  };
  for (int u = 0; u < rig.width; u += 8) look(u, 0), look(u, rig.height - 1);
  for (int v = 0; v < rig.height; v += 8) look(0, v), look(rig.width - 1, v);
  look(rig.width - 1, rig.height - 1);
  field_half_angle_ = widest > 0.0 ? widest : M_PI_2;
}

ViewCone ColouringPipeline::viewCone(const RegisteredScanView& scan) {
  // the body's motion from the scan poses of the last 2 s (a loop correction's jump only widens it)
  if (last_scan_pose_) {
    const double dt = (scan.utime - last_scan_pose_->first) * 1e-6;
    const Pose3& last = last_scan_pose_->second;
    if (dt > 0.0)
      motion_.push_back({scan.utime, so3::Log(Mat3(last.linear().transpose() * scan.T_W_I.linear())).norm() / dt,
                         (scan.T_W_I.translation() - last.translation()).norm() / dt});
  }
  last_scan_pose_ = std::make_pair(scan.utime, scan.T_W_I);
  while (!motion_.empty() && motion_.front().utime < scan.utime - 2000000) motion_.pop_front();
  double rate = 0.0, speed = 0.0;
  for (const Motion& m : motion_) rate = std::max(rate, m.rate), speed = std::max(speed, m.speed);

  ViewCone cone;
  const Pose3 T_W_C = scan.T_W_I * camera_.rig().T_I_C;
  cone.centre = T_W_C.translation();
  cone.axis = T_W_C.linear().col(2);
  // images of the window lie within max_time_difference of a point, which lies within the sweep
  const double window = options_.max_time_difference + std::max(0.0, (scan.utime - scan.cloud_utime) * 1e-6);
  const double turn = 1.5 * rate * window;
  cone.half_angle = field_half_angle_ + options_.view_margin_deg * M_PI / 180.0 + turn;
  cone.travel = 1.5 * speed * window + camera_.rig().T_I_C.translation().norm() * turn + 0.2;
  cone.prepare();
  return cone;
}

void ColouringPipeline::addPose(int64_t utime, const Pose3& T_W_I) { poses_.add(utime, T_W_I); }

bool ColouringPipeline::addScan(const RegisteredScanView& scan, std::string* error) {
  if (scan.utime <= last_scan_utime_) {
    *error = "scan stamp not after the previous scan";
    return false;
  }
  if (!scan.T_W_I.matrix().allFinite()) {
    *error = "scan pose is not finite";
    return false;
  }
  last_scan_utime_ = scan.utime;
  newest_scan_end_ = scan.utime;
  poses_.add(scan.utime, scan.T_W_I);
  ++stats_.scans;
  const int64_t anchor = keyframes_.empty() ? -1 : keyframes_.rbegin()->first;
  map_.setTime(scan.utime);
  ActiveScan active{++scan_seq_, INT64_MAX, INT64_MIN, std::move(spare_points_)};
  spare_points_ = {};
  active.points.clear();
  active.points.reserve(scan.num_points);
  const Eigen::Vector3f body = scan.T_W_I.translation().cast<float>();
  const float reach = static_cast<float>(options_.max_depth + options_.map_margin);
  const ViewCone cone = viewCone(scan);
  // first the points the map takes, then into the map in scan order (the same ids)
  accepted_.clear();
  accepted_points_.clear();
  for (int j = 0; j < scan.num_points; ++j) {
    const Eigen::Vector3f p(scan.x[j], scan.y[j], scan.z[j]);
    const float dt = scan.time_offset ? scan.time_offset[j] : 0.0f;
    if (!p.allFinite() || !std::isfinite(dt) || p.cwiseAbs().maxCoeff() > 1e5f) {
      ++stats_.points_rejected;
      continue;
    }
    if ((p - body).squaredNorm() > reach * reach) {
      ++stats_.points_out_of_reach;
      continue;
    }
    if (options_.map_only_in_view && !cone.contains(p.cast<double>())) {
      ++stats_.points_out_of_view;
      continue;
    }
    accepted_.push_back(j);
    accepted_points_.push_back(p);
  }
  map_.addPoints(accepted_points_, anchor, &accepted_ids_);
  if (last_scan_.size() < map_.size()) last_scan_.resize(map_.size(), 0);
  for (size_t k = 0; k < accepted_.size(); ++k) {
    const int j = accepted_[k];
    const float dt = scan.time_offset ? scan.time_offset[j] : 0.0f;
    const int64_t t = scan.cloud_utime + static_cast<int64_t>(std::llround(double(dt) * 1e6));
    const uint32_t id = accepted_ids_[k];
    last_scan_[id] = active.seq;
    active.points.emplace_back(id, t);
    active.t_min = std::min(active.t_min, t);
    active.t_max = std::max(active.t_max, t);
  }
  stats_.points_in += static_cast<int64_t>(active.points.size());
  if (!active.points.empty()) active_.push_back(std::move(active));
  // keep the scans an image still to come may need (a generous second beyond the window)
  const int64_t keep_from = newest_scan_end_ - 2 * windowUs() - 1000000;
  while (!active_.empty() && active_.front().t_max < keep_from) {
    spare_points_ = std::move(active_.front().points);
    active_.pop_front();
  }
  poses_.dropBefore(keep_from);
  if (last_prune_utime_ == INT64_MIN) {
    last_prune_utime_ = scan.utime;
  } else if (scan.utime - last_prune_utime_ >= kPrunePeriodUs) {
    pruneUncolourable();
    last_prune_utime_ = scan.utime;
  }
  processReady(false);
  afterTileChanges(map_.evictIdle(scan.utime));
  return true;
}

bool ColouringPipeline::addImage(ColourImage image, std::string* error) {
  if (image.utime <= last_image_utime_) {
    *error = "image stamp not after the previous image";
    return false;
  }
  if (image.pixels.cols != camera_.rig().width || image.pixels.rows != camera_.rig().height) {
    *error = "image size " + std::to_string(image.pixels.cols) + "x" + std::to_string(image.pixels.rows) +
             " differs from the rig's camera";
    return false;
  }
  last_image_utime_ = image.utime;
  images_.push_back(std::move(image));
  processReady(false);
  while (images_.size() > static_cast<size_t>(std::max(1, options_.max_pending_images))) {
    images_.pop_front();
    ++stats_.images_dropped;
  }
  return true;
}

void ColouringPipeline::flush() { processReady(true); }

void ColouringPipeline::processReady(bool flushing) {
  while (!images_.empty()) {
    const ColourImage& image = images_.front();
    const bool scans_in = newest_scan_end_ != INT64_MIN && newest_scan_end_ >= image.utime + windowUs();
    if (!scans_in && !flushing) return;
    if (!processImage(image)) {
      // no pose yet: wait for one unless the poses have moved past it or the stream ended
      if (!flushing && poses_.newest() < image.utime) return;
      ++stats_.images_without_pose;
    }
    images_.pop_front();
  }
}

bool ColouringPipeline::processImage(const ColourImage& image) {
  Pose3 T_W_I;
  if (!poses_.at(image.utime, &T_W_I)) return false;
  ++stats_.images;
  const Pose3 T_W_C = T_W_I * camera_.rig().T_I_C;
  const Pose3 T_C_W = T_W_C.inverse();
  windowPoints(image.utime - windowUs(), image.utime + windowUs(), &window_seen_, &window_ids_);
  projectedPoints(window_ids_, T_C_W, &candidates_);
  const std::vector<Candidate>& candidates = candidates_;
  stats_.projected += static_cast<int64_t>(candidates.size());

  depth_.clear();
  depth_.splatNearest(candidates, [](const Candidate& c) { return std::make_pair(c.pixel, c.z); });

  const double exposure_scale = exposureScale(image);
  visibleSamples(image, candidates, exposure_scale, &sampled_ids_, &observed_);
  const double gain = options_.estimate_gain ? imageGain(sampled_ids_, observed_, &gain_observed_, &gain_mapped_) : 1.0;
  stats_.last_gain = gain;
  accumulateSamples(image, T_W_C, candidates, sampled_ids_, observed_, gain);
  return true;
}

void ColouringPipeline::windowPoints(int64_t t0, int64_t t1, std::vector<uint64_t>* seen,
                                     std::vector<uint32_t>* ids) const {
  // the map points measured within the window, each once (in the order first measured)
  std::vector<uint32_t>& window_ids = *ids;
  window_ids.clear();
  // a bit per map point, cleared per image: a few kB, so the test stays in the first-level cache
  // (a stamp per point, as before, is 4 bytes a point and missed it)
  seen->assign((map_.size() + 63) / 64, 0);
  // without branches: whether a point is taken is as good as random (a window cuts through its
  // scans, and most points were measured by the scans before too)
  size_t taken = 0;
  auto gather = [&](const ActiveScan& scan, auto in_window) {
    for (const auto& [id, t] : scan.points) {
      uint64_t& word = (*seen)[id >> 6];
      const uint64_t bit = uint64_t{1} << (id & 63);
      const bool take = in_window(t) & !(word & bit);
      word |= take ? bit : 0;
      window_ids[taken] = id;
      taken += take;
    }
  };
  for (const ActiveScan& scan : active_) {
    if (scan.t_max < t0 || scan.t_min > t1) continue;
    window_ids.resize(taken + scan.points.size());
    // most of the window's scans lie in it whole: their points need no time test
    if (scan.t_min >= t0 && scan.t_max <= t1)
      gather(scan, [](int64_t) { return true; });
    else
      gather(scan, [t0, t1](int64_t t) { return (t >= t0) & (t <= t1); });
  }
  window_ids.resize(taken);
}

void ColouringPipeline::projectedPoints(const std::vector<uint32_t>& ids, const Pose3& T_C_W,
                                        std::vector<Candidate>* candidates) const {
  // positions are read ahead (a map point is some 40 bytes anywhere in the map: the read, not the
  // arithmetic, is what a point costs); each point's address is found once (a deque's indexing is
  // no single add), for the read-ahead, and kept in a ring until its turn
  candidates->clear();
  const MapPoint* ahead[kReadAhead];
  for (size_t i = 0; i < std::min(kReadAhead, ids.size()); ++i) ahead[i] = &map_.point(ids[i]);
  for (size_t i = 0; i < ids.size(); ++i) {
    const MapPoint& mp = *ahead[i % kReadAhead];
    if (i + kReadAhead < ids.size()) {
      ahead[i % kReadAhead] = &map_.point(ids[i + kReadAhead]);
      __builtin_prefetch(ahead[i % kReadAhead]);
    }
    const uint32_t id = ids[i];
    const Eigen::Vector3d p_C = T_C_W * mp.position.cast<double>();
    if (p_C.z() < options_.min_depth || p_C.z() > options_.max_depth) continue;
    Eigen::Vector2d px;
    if (!camera_.project(p_C, &px, 0.0)) continue;
    candidates->push_back({id, px, p_C.z()});
  }
}

double ColouringPipeline::exposureScale(const ColourImage& image) {
  if (!(options_.use_exposure_time && image.exposure_time > 0)) return 1.0;
  if (reference_exposure_ <= 0.0) reference_exposure_ = image.exposure_time;
  return reference_exposure_ / image.exposure_time;
}

void ColouringPipeline::visibleSamples(const ColourImage& image, const std::vector<Candidate>& candidates,
                                       double exposure_scale, std::vector<uint32_t>* ids,
                                       std::vector<Eigen::Vector3f>* observed) {
  const double b = options_.border_px, w = camera_.rig().width - 1 - b, h = camera_.rig().height - 1 - b;
  ids->clear();
  observed->clear();
  for (const Candidate& c : candidates) {
    if (c.pixel.x() < b || c.pixel.y() < b || c.pixel.x() > w || c.pixel.y() > h) continue;
    if (!depth_.visible(c.pixel, c.z)) {
      ++stats_.occluded;
      continue;
    }
    const double scale = exposure_scale / camera_.vignette(c.pixel, options_.vignetting);
    ids->push_back(c.id);
    observed->push_back(image.sample(c.pixel) * static_cast<float>(scale));
  }
}

double ColouringPipeline::imageGain(const std::vector<uint32_t>& ids, const std::vector<Eigen::Vector3f>& observed,
                                    std::vector<Eigen::Vector3f>* gain_observed,
                                    std::vector<Eigen::Vector3f>* gain_mapped) {
  // the samples of points the map has coloured at least twice, against the map's colour
  gain_observed->clear();
  gain_mapped->clear();
  for (size_t i = 0; i < ids.size(); ++i) {
    if (i + kReadAhead < ids.size()) __builtin_prefetch(&map_.point(ids[i + kReadAhead]));
    const MapPoint& mp = map_.point(ids[i]);
    if (mp.count >= 2) {
      gain_observed->push_back(observed[i]);
      gain_mapped->push_back(mp.colour);
    }
  }
  const GainEstimate g =
      estimateGain(*gain_observed, *gain_mapped, options_.gain_min_pairs, options_.gain_min, options_.gain_max);
  if (!g.valid) return 1.0;
  ++stats_.gain_estimates;
  return g.gain;
}

void ColouringPipeline::accumulateSamples(const ColourImage& image, const Pose3& T_W_C,
                                          const std::vector<Candidate>& candidates, const std::vector<uint32_t>& ids,
                                          const std::vector<Eigen::Vector3f>& observed, double gain) {
  AccumulationOptions acc{options_.outlier_threshold, options_.outlier_min_count, options_.max_count};
  size_t k = 0;
  for (const Candidate& c : candidates) {
    if (k >= ids.size() || ids[k] != c.id) continue;
    if (k + kReadAhead < ids.size()) __builtin_prefetch(&map_.point(ids[k + kReadAhead]));
    const Eigen::Vector3f col = (observed[k] / static_cast<float>(gain)).cwiseMin(255.0f);
    ++k;
    if (!map_.accumulate(c.id, col, acc)) {
      ++stats_.outliers;
      continue;
    }
    ++stats_.accepted;
    markRecoloured(c.id);
    if (observer_) observer_({c.id, image.utime, c.pixel, T_W_C.translation(), col});
  }
}

void ColouringPipeline::pruneUncolourable() {
  const uint32_t oldest_kept = active_.empty() ? scan_seq_ + 1 : active_.front().seq;
  stats_.points_pruned += static_cast<int64_t>(
      map_.removeUncoloured([&](uint32_t id) { return id >= last_scan_.size() || last_scan_[id] < oldest_kept; }));
}

void ColouringPipeline::markRecoloured(uint32_t id) {
  if (recoloured_flag_.size() < map_.size()) recoloured_flag_.resize(map_.size(), 0);
  if (!recoloured_flag_[id]) {
    recoloured_flag_[id] = 1;
    recoloured_.push_back(id);
  }
}

void ColouringPipeline::afterTileChanges(std::vector<uint32_t> freed) {
  if (!freed.empty()) {
    std::sort(freed.begin(), freed.end());
    auto gone = [&](uint32_t id) { return std::binary_search(freed.begin(), freed.end(), id); };
    // the scans an image may still need touch only resident tiles (idle_s > their span): this
    // only guards against a caller that never takes the recoloured ids
    for (ActiveScan& s : active_)
      s.points.erase(std::remove_if(s.points.begin(), s.points.end(), [&](const auto& pt) { return gone(pt.first); }),
                     s.points.end());
    recoloured_.erase(std::remove_if(recoloured_.begin(), recoloured_.end(), gone), recoloured_.end());
    for (uint32_t id : freed)
      if (id < recoloured_flag_.size()) recoloured_flag_[id] = 0;
  }
  for (uint32_t id : map_.takeMovedOnReload()) markRecoloured(id);
}

void ColouringPipeline::settleMap() { afterTileChanges(map_.settleSpilledTiles()); }

std::vector<uint32_t> ColouringPipeline::takeRecoloured() {
  std::vector<uint32_t> out;
  if (recoloured_.size() * 16 >= recoloured_flag_.size()) {
    // many (a sweep's worth): the flags, read in id order, are the sorted list without a sort
    out.reserve(recoloured_.size());
    for (uint32_t id = 0; id < recoloured_flag_.size(); ++id) {
      if (!recoloured_flag_[id]) continue;
      recoloured_flag_[id] = 0;
      out.push_back(id);
    }
    recoloured_.clear();
    return out;
  }
  out.swap(recoloured_);
  for (uint32_t id : out) recoloured_flag_[id] = 0;
  std::sort(out.begin(), out.end());
  return out;
}

void ColouringPipeline::addKeyframe(int64_t id, int64_t utime, const Pose3& T_W_I) {
  if (!T_W_I.matrix().allFinite()) return;
  if (keyframes_.emplace(id, std::make_pair(utime, T_W_I)).second) map_.setAnchorPose(id, T_W_I);
}

int ColouringPipeline::applyCorrection(const std::map<int64_t, Pose3>& corrected, const Pose3& unlisted) {
  std::map<int64_t, Pose3> delta;
  for (auto& [id, keyframe] : keyframes_) {
    Pose3& current = keyframe.second;
    const auto listed = corrected.find(id);
    const Pose3 pose = listed != corrected.end() ? listed->second : unlisted * current;
    if (!pose.matrix().allFinite()) continue;
    const Pose3 d = pose * current.inverse();
    if ((d.matrix() - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff() < 1e-12) continue;
    delta[id] = d;
    current = pose;
    map_.setAnchorPose(id, pose);
  }
  if (delta.empty()) return 0;
  map_.transform([&](int64_t anchor, Pose3* T) {
    auto it = delta.find(anchor);
    if (it == delta.end()) return false;
    *T = it->second;
    return true;
  });
  // points that went to a tile on disk leave the scans (no image can colour them there) and are
  // published when their tile comes back
  const auto& remap = map_.lastRemap();
  std::vector<uint32_t> last_scan(map_.size(), 0);
  for (size_t old = 0; old < std::min(last_scan_.size(), remap.size()); ++old)
    if (remap[old] != ColourMap::kGone) last_scan[remap[old]] = std::max(last_scan[remap[old]], last_scan_[old]);
  last_scan_.swap(last_scan);
  for (ActiveScan& s : active_) {
    for (auto& pt : s.points) pt.first = remap[pt.first];
    s.points.erase(
        std::remove_if(s.points.begin(), s.points.end(), [](const auto& pt) { return pt.first == ColourMap::kGone; }),
        s.points.end());
  }
  std::vector<uint32_t> rec;
  for (uint32_t id : recoloured_)
    if (remap[id] != ColourMap::kGone) rec.push_back(remap[id]);
  std::sort(rec.begin(), rec.end());
  rec.erase(std::unique(rec.begin(), rec.end()), rec.end());
  // every point that moved is "recoloured" (its published position changed)
  recoloured_flag_.assign(map_.size(), 0);
  recoloured_.clear();
  for (uint32_t id = 0; id < map_.size(); ++id) {
    const MapPoint& mp = map_.point(id);
    if (mp.live() && mp.coloured() && (delta.count(mp.anchor) || std::binary_search(rec.begin(), rec.end(), id))) {
      recoloured_flag_[id] = 1;
      recoloured_.push_back(id);
    }
  }
  return static_cast<int>(delta.size());
}

}  // namespace livo::colour
