#include "livo/vio/vio_estimator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "livo/plane.hpp"

namespace livo::vio {

namespace {
constexpr int kMaxCandidatesPerCell = 8;  // gradient evaluations per new-point cell
}  // namespace

std::vector<Vec3> voxelPoints(const float* x, const float* y, const float* z, size_t n, const MapOptions& o,
                              std::vector<Vec3>* normals) {
  // group the finite points by voxel (CSR: first point of each voxel in arrival order)
  const double inv = 1.0 / o.voxel_size;
  std::unordered_map<uint64_t, uint32_t> voxel_of;
  voxel_of.reserve(n / 4 + 16);
  std::vector<uint32_t> group(n, UINT32_MAX), count;
  std::vector<Vec3> first;
  for (size_t i = 0; i < n; ++i) {
    const Vec3 p(x[i], y[i], z[i]);
    if (!p.allFinite()) continue;
    const auto [it, added] = voxel_of.emplace(voxelKeyOf(p, inv), static_cast<uint32_t>(first.size()));
    if (added) {
      first.push_back(p);
      count.push_back(0);
    }
    group[i] = it->second;
    ++count[it->second];
  }
  const bool snap = o.plane_snap_max_rms > 0.0, with_normals = normals != nullptr && o.normal_max_rms > 0.0;
  if (normals != nullptr) normals->assign(first.size(), Vec3::Zero());
  if (!snap && !with_normals) return first;
  std::vector<uint32_t> start(first.size() + 1, 0);
  for (size_t g = 0; g < first.size(); ++g) start[g + 1] = start[g] + count[g];
  std::vector<Vec3> members(start.back());
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (size_t i = 0; i < n; ++i)
    if (group[i] != UINT32_MAX) members[fill[group[i]]++] = Vec3(x[i], y[i], z[i]);
  // A flat voxel (its points within max_rms of their plane, spread twice as wide as thick): for the
  // snap its first point onto the plane (the range noise normal to the surface averages out; a
  // position along the surface is as good as any for a patch), for the normal also spread across
  // in both directions (kMinNormalSpread of the voxel: one ring's arc is a line, whatever its
  // scatter says)
  constexpr double kMinNormalSpread = 0.15;
  const double snap_ms = o.plane_snap_max_rms * o.plane_snap_max_rms, normal_ms = o.normal_max_rms * o.normal_max_rms;
  const double min_spread = kMinNormalSpread * kMinNormalSpread * o.voxel_size * o.voxel_size;
  PlaneFit fit;
  for (size_t g = 0; g < first.size(); ++g) {
    const int m = static_cast<int>(count[g]);
    const bool try_snap = snap && m >= o.plane_snap_min_points, try_normal = with_normals && m >= o.normal_min_points;
    if (!(try_snap || try_normal) || !fitPlane(members.data() + start[g], m, &fit)) continue;
    if (fit.spread[1] < 4.0 * fit.spread[0]) continue;
    if (try_normal && fit.spread[0] <= normal_ms && fit.spread[1] >= min_spread) (*normals)[g] = fit.plane.normal;
    if (try_snap && fit.spread[0] <= snap_ms) first[g] = fit.plane.project(first[g]);
  }
  return first;
}

VioEstimator::VioEstimator(const VioOptions& options, const CameraRig& camera)
    : options_(options),
      camera_(camera),
      map_(options.map),
      depth_(camera.width, camera.height, options.selection.depth_cell_px),
      shutter_(RollingShutter::fromReadout(camera.rolling_shutter_s, camera.height)) {
  validate(options_);
}

void VioEstimator::reset() {
  map_.clear();
  scans_.clear();
}

void VioEstimator::addScan(int64_t utime, const float* x, const float* y, const float* z, size_t n) {
  Scan s;
  s.utime = utime;
  s.points = voxelPoints(x, y, z, n, options_.map, &s.normals);
  // newest last; equal stamps keep arrival order
  auto it = std::upper_bound(scans_.begin(), scans_.end(), utime, [](int64_t t, const Scan& e) { return t < e.utime; });
  scans_.insert(it, std::move(s));
  while (static_cast<int>(scans_.size()) > options_.map.recent_scans) scans_.pop_front();
}

void VioEstimator::addScan(int64_t utime, const std::vector<Vec3>& points) {
  std::vector<float> x(points.size()), y(points.size()), z(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    x[i] = static_cast<float>(points[i].x());
    y[i] = static_cast<float>(points[i].y());
    z[i] = static_cast<float>(points[i].z());
  }
  addScan(utime, x.data(), y.data(), z.data(), points.size());
}

size_t VioEstimator::recentScanPoints() const {
  size_t n = 0;
  for (const auto& s : scans_) n += s.points.size();
  return n;
}

void VioEstimator::applyCorrection(const Pose3& T) {
  map_.transform(T);
  for (auto& s : scans_) {
    for (auto& p : s.points) p = T * p;
    for (auto& nrm : s.normals) nrm = T.linear() * nrm;
  }
}

void VioEstimator::fillDepth(const Pose3& T_W_C) {
  depth_.clear();
  const Pose3 T_C_W = T_W_C.inverse();
  const double zmin = options_.selection.min_depth;
  Eigen::Vector2d px;
  auto add = [&](const Vec3& p_W) {
    const Vec3 p_C = T_C_W * p_W;
    if (p_C.z() >= zmin && camera_.project(p_C, &px)) depth_.add(px, static_cast<float>(p_C.z()));
  };
  for (const auto& s : scans_)
    for (const auto& p : s.points) add(p);
  for (const auto& m : map_.points()) add(m.position);
}

bool VioEstimator::makeObservation(const Eigen::Vector2d& pixel, const GreyImage& image, const ReferenceView& view,
                                   const Mat6& pose_cov_W, PatchObservation* obs) const {
  const int levels = pyramid_.levels();
  obs->pixels.resize(static_cast<size_t>(levels) * kStoredArea);
  if (!extractStoredPatches(pyramid_, pixel, levels, obs->pixels.data())) return false;
  const int gl = std::min(1, levels - 1);
  obs->utime = image.utime;
  obs->view = view;
  obs->view.pixel = pixel;
  obs->pose_cov_W = pose_cov_W.cast<float>();
  obs->exposure_time = image.exposure_time;
  obs->gradient = patchGradient(pyramid_, gl, ImagePyramid::toLevel(pixel, gl));
  obs->error = 0.0f;
  return true;
}

ImageResult VioEstimator::processImage(const GreyImage& image, const FilterState& prior, const StateCovariance& P,
                                       const Vec3& body_rate) {
  ImageResult r;
  r.state = prior;
  r.covariance = P;
  const int levels = options_.photometric.pyramid_levels;
  pyramid_.build(image.pixels, levels);
  RollingShutter shutter = shutter_;
  shutter.omega_I = body_rate;
  // the camera when the image was really taken: the stamp plus the camera's time shift
  const Pose3 T_W_C = advanced(prior, body_rate, prior.camera.dt).pose() * prior.camera.pose();
  fillDepth(T_W_C);
  std::vector<TrackedPatch> tracked =
      selectPatches(map_, camera_, T_W_C, prior.camera, image.utime, image.exposure_time, depth_, levels,
                    options_.selection, &r.selection);
  bool updated = false;
  if (static_cast<int>(tracked.size()) < options_.update.min_patches) {
    r.why = map_.size() == 0 ? std::string("the point-patch map is empty")
                             : "too few map points in view (" + std::to_string(tracked.size()) + " < " +
                                   std::to_string(options_.update.min_patches) + ")";
  } else {
    const DirectUpdateResult u =
        directUpdate(prior, P, pyramid_, camera_, options_.photometric, options_.update, &tracked, shutter);
    r.iterations = u.iterations;
    r.num_measurements = u.num_measurements;
    r.patches = u.patches;
    r.consistency = u.consistency;
    r.cost_prior = u.cost_prior;
    r.cost_post = u.cost_post;
    r.valid = updated = u.valid;
    r.why = u.why;
    if (u.valid) {
      r.state = u.state;
      r.covariance = u.covariance;
    }
  }
  maintain(image, r.state, shutter, updated, tracked, &r);
  map_.prune((r.state.pose() * r.state.camera.pose()).translation());
  r.map_points = map_.size();
  return r;
}

void VioEstimator::maintain(const GreyImage& image, const FilterState& x, const RollingShutter& shutter, bool refresh,
                            const std::vector<TrackedPatch>& tracked, ImageResult* r) {
  const MaintenanceOptions& mo = options_.maintenance;
  const SelectionOptions& so = options_.selection;
  const CameraRig& rig = camera_.rig();
  const int cell = std::max(8, mo.new_point_cell_px);
  const int cols = (rig.width + cell - 1) / cell, rows = (rig.height + cell - 1) / cell;
  std::vector<char> occupied(static_cast<size_t>(cols) * rows, 0);
  const double border = patchBorder(pyramid_.levels());
  // the body when the image was really taken (the camera's time shift) and the camera there
  const FilterState at_image = advanced(x, shutter.omega_I, x.camera.dt);
  const Pose3 T_I_C = x.camera.pose();
  const Pose3 T_W_C = at_image.pose() * T_I_C;
  const Pose3 T_C_W = T_W_C.inverse();
  const Vec3 c_W = T_W_C.translation();
  // where a point is seen (its row's pose under a rolling shutter) and the view a patch cut there
  // is in: that row's body pose and motion, and the calibration in use
  ShutterProjection sp;
  auto seen = [&](const Vec3& p_W) {
    return projectThroughShutter(camera_, T_I_C, at_image, shutter, p_W, &sp, border, /*with_jacobian=*/false);
  };
  auto viewAt = [&](double row_dt) {
    ReferenceView v;
    v.T_W_I = advanced(at_image, shutter.omega_I, row_dt).pose();
    v.omega_I = shutter.omega_I;
    v.vel_W = x.vel;
    v.T_I_C = T_I_C;
    v.time_shift = x.camera.dt;
    return v;
  };
  // the pose covariance the references cut now carry, rotation in the world frame
  Mat6 J = Mat6::Identity();
  J.topLeftCorner<3, 3>() = x.rot;
  const Mat6 P_pose = r->covariance.topLeftCorner<6, 6>();
  const Mat6 pose_cov_W = J * (0.5 * (P_pose + P_pose.transpose())) * J.transpose();
  auto cellOf = [&](const Eigen::Vector2d& px) {
    return static_cast<size_t>(static_cast<int>(px.y()) / cell * cols + static_cast<int>(px.x()) / cell);
  };

  // tracked points: seen now; a new patch when the view or the photometric error changed enough
  Eigen::Vector2d px;
  for (const TrackedPatch& t : tracked) {
    MapPoint& m = map_.point(t.point);
    m.last_seen = image.utime;
    if (!seen(m.position)) continue;
    px = sp.pixel;
    occupied[cellOf(px)] = 1;
    if (!refresh || !t.active) continue;
    m.observations[static_cast<size_t>(t.observation)].error = t.rms;
    if (t.ncc < mo.outlier_ncc) continue;  // occluded or changed: do not learn it
    const Vec3 ray = m.position - c_W;
    double min_angle = std::numeric_limits<double>::infinity(), ratio = 1.0;
    for (const auto& obs : m.observations) {
      const Vec3 ray_obs = m.position - obs.cameraCentre();
      const double a = angleBetweenDeg(ray, ray_obs);
      if (a < min_angle) {
        min_angle = a;
        ratio = ray.norm() / std::max(1e-9, ray_obs.norm());
      }
    }
    ratio = std::max(ratio, 1.0 / ratio);
    if (min_angle > mo.refresh_angle_deg || ratio > mo.refresh_distance_ratio || t.rms > mo.refresh_error) {
      PatchObservation obs;
      if (makeObservation(px, image, viewAt(sp.dt), pose_cov_W, &obs)) {
        map_.addObservation(t.point, std::move(obs));
        ++r->new_patches;
      }
    }
  }

  // new points: per free cell the best-textured recent LiDAR point (newest scan first)
  struct Best {
    float gradient = -1.0f;
    int evaluated = 0;
    Vec3 p = Vec3::Zero(), normal = Vec3::Zero();
    Eigen::Vector2d px = Eigen::Vector2d::Zero();
    double dt = 0.0;  // row time
  };
  std::vector<Best> best(occupied.size());
  const int gl = std::min(1, pyramid_.levels() - 1);
  for (auto s = scans_.rbegin(); s != scans_.rend(); ++s) {
    for (size_t k = 0; k < s->points.size(); ++k) {
      const Vec3& p = s->points[k];
      const Vec3 p_C = T_C_W * p;
      if (p_C.z() < so.min_depth || p_C.z() > so.max_depth || !seen(p)) continue;
      px = sp.pixel;
      const size_t c = cellOf(px);
      Best& b = best[c];
      if (occupied[c] || b.evaluated >= kMaxCandidatesPerCell || map_.find(p) >= 0) continue;
      ++r->candidates;
      if (depth_.occluded(px, p_C.z(), so.occlusion_tolerance, so.occlusion_tolerance_rel) ||
          depth_.depthEdge(px, p_C.z(), so.depth_edge_radius_px, so.depth_edge_tolerance,
                           so.depth_edge_tolerance_rel)) {
        ++r->candidates_hidden;
        continue;
      }
      ++b.evaluated;
      const float g = patchGradient(pyramid_, gl, ImagePyramid::toLevel(px, gl));
      if (g > b.gradient) {
        b.gradient = g;
        b.p = p;
        b.normal = s->normals[k];
        b.px = px;
        b.dt = sp.dt;
      }
    }
  }
  for (const Best& b : best) {
    if (r->new_points >= mo.max_new_points) break;
    if (b.gradient < mo.min_gradient) {
      r->candidates_weak += b.evaluated > 0;
      continue;
    }
    PatchObservation obs;
    if (!makeObservation(b.px, image, viewAt(b.dt), pose_cov_W, &obs)) continue;
    if (map_.add(b.p, image.utime, std::move(obs), b.normal) >= 0) ++r->new_points;
  }
}

}  // namespace livo::vio
