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

// The camera when the image was really taken (the stamp plus the camera's time shift) at the
// posterior x: where it sees a point (its row's pose under a rolling shutter) and the view a patch
// cut there is in (that row's body pose and motion, and the calibration in use).
struct VioEstimator::ImageCamera {
  ImageCamera(const FilterState& x, const RollingShutter& shutter_in, double border_in)
      : at_image(advanced(x, shutter_in.omega_I, x.camera.dt)),
        shutter(shutter_in),
        T_I_C(x.camera.pose()),
        T_W_C(at_image.pose() * T_I_C),
        T_C_W(T_W_C.inverse()),
        c_W(T_W_C.translation()),
        vel_W(x.vel),
        time_shift(x.camera.dt),
        border(border_in) {}

  bool sees(const CameraProjection& camera, const Vec3& p_W, ShutterProjection* sp) const {
    return projectThroughShutter(camera, T_I_C, at_image, shutter, p_W, sp, border, /*with_jacobian=*/false);
  }
  ReferenceView viewAt(double row_dt) const {
    ReferenceView v;
    v.T_W_I = advanced(at_image, shutter.omega_I, row_dt).pose();
    v.omega_I = shutter.omega_I;
    v.vel_W = vel_W;
    v.T_I_C = T_I_C;
    v.time_shift = time_shift;
    return v;
  }

  FilterState at_image;
  RollingShutter shutter;
  Pose3 T_I_C, T_W_C, T_C_W;
  Vec3 c_W, vel_W;
  double time_shift, border;
};

// The best-textured recent LiDAR point of a free cell.
struct VioEstimator::NewPointCandidate {
  float gradient = -1.0f;
  int evaluated = 0;
  Vec3 p = Vec3::Zero(), normal = Vec3::Zero();
  Eigen::Vector2d px = Eigen::Vector2d::Zero();
  double dt = 0.0;  // row time
};

namespace {

// The pose covariance the references cut now carry, rotation in the world frame.
Mat6 worldPoseCovariance(const Mat3& R_W_I, const StateCovariance& P) {
  Mat6 J = Mat6::Identity();
  J.topLeftCorner<3, 3>() = R_W_I;
  const Mat6 P_pose = P.topLeftCorner<6, 6>();
  return J * (0.5 * (P_pose + P_pose.transpose())) * J.transpose();
}

// Whether the view of a tracked point from c_W turned or moved far enough from all its patches' (or
// its reference's residual RMS grew enough) for a new patch.
bool viewChanged(const MapPoint& m, const Vec3& c_W, float rms, const MaintenanceOptions& mo) {
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
  return min_angle > mo.refresh_angle_deg || ratio > mo.refresh_distance_ratio || rms > mo.refresh_error;
}

}  // namespace

void VioEstimator::maintain(const GreyImage& image, const FilterState& x, const RollingShutter& shutter, bool refresh,
                            const std::vector<TrackedPatch>& tracked, ImageResult* r) {
  const ImageCamera cam(x, shutter, patchBorder(pyramid_.levels()));
  const Mat6 pose_cov_W = worldPoseCovariance(x.rot, r->covariance);
  const CellGrid grid(camera_.rig().width, camera_.rig().height, options_.maintenance.new_point_cell_px);
  std::vector<char> occupied(grid.size(), 0);
  r->new_patches += refreshTracked(image, cam, pose_cov_W, refresh, tracked, grid, &occupied);
  const std::vector<NewPointCandidate> best = newPointCandidates(cam, grid, occupied, r);
  addNewPoints(image, cam, pose_cov_W, best, r);
}

int VioEstimator::refreshTracked(const GreyImage& image, const ImageCamera& cam, const Mat6& pose_cov_W, bool refresh,
                                 const std::vector<TrackedPatch>& tracked, const CellGrid& grid,
                                 std::vector<char>* occupied) {
  const MaintenanceOptions& mo = options_.maintenance;
  int added = 0;
  ShutterProjection sp;
  for (const TrackedPatch& t : tracked) {
    MapPoint& m = map_.point(t.point);
    m.last_seen = image.utime;
    if (!cam.sees(camera_, m.position, &sp)) continue;
    (*occupied)[grid.of(sp.pixel)] = 1;
    if (!refresh || !t.active) continue;
    m.observations[static_cast<size_t>(t.observation)].error = t.rms;
    if (t.ncc < mo.outlier_ncc) continue;  // occluded or changed: do not learn it
    if (!viewChanged(m, cam.c_W, t.rms, mo)) continue;
    PatchObservation obs;
    if (makeObservation(sp.pixel, image, cam.viewAt(sp.dt), pose_cov_W, &obs)) {
      map_.addObservation(t.point, std::move(obs));
      ++added;
    }
  }
  return added;
}

std::vector<VioEstimator::NewPointCandidate> VioEstimator::newPointCandidates(const ImageCamera& cam,
                                                                              const CellGrid& grid,
                                                                              const std::vector<char>& occupied,
                                                                              ImageResult* r) const {
  const SelectionOptions& so = options_.selection;
  std::vector<NewPointCandidate> best(occupied.size());
  const int gl = std::min(1, pyramid_.levels() - 1);
  ShutterProjection sp;
  for (auto s = scans_.rbegin(); s != scans_.rend(); ++s) {
    for (size_t k = 0; k < s->points.size(); ++k) {
      const Vec3& p = s->points[k];
      const Vec3 p_C = cam.T_C_W * p;
      if (p_C.z() < so.min_depth || p_C.z() > so.max_depth || !cam.sees(camera_, p, &sp)) continue;
      const Eigen::Vector2d px = sp.pixel;
      const size_t c = grid.of(px);
      NewPointCandidate& b = best[c];
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
  return best;
}

void VioEstimator::addNewPoints(const GreyImage& image, const ImageCamera& cam, const Mat6& pose_cov_W,
                                const std::vector<NewPointCandidate>& best, ImageResult* r) {
  for (const NewPointCandidate& b : best) {
    if (r->new_points >= options_.maintenance.max_new_points) break;
    if (b.gradient < options_.maintenance.min_gradient) {
      r->candidates_weak += b.evaluated > 0;
      continue;
    }
    PatchObservation obs;
    if (!makeObservation(b.px, image, cam.viewAt(b.dt), pose_cov_W, &obs)) continue;
    if (map_.add(b.p, image.utime, std::move(obs), b.normal) >= 0) ++r->new_points;
  }
}

}  // namespace livo::vio
