#include "livo/vio/point_selection.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>

#include "livo/time.hpp"

namespace livo::vio {

DepthGrid::DepthGrid(int width, int height, int cell_px)
    : cell_(std::max(1, cell_px)), cols_((width + cell_ - 1) / cell_), rows_((height + cell_ - 1) / cell_) {
  cells_.assign(static_cast<size_t>(cols_) * rows_, kEmpty);
}

void DepthGrid::clear() {
  // only the cells points went into: most of the grid stays empty from image to image
  for (const int i : filled_) cells_[static_cast<size_t>(i)] = kEmpty;
  filled_.clear();
}

int DepthGrid::index(const Eigen::Vector2d& pixel) const {
  const int cx = static_cast<int>(pixel.x()) / cell_, cy = static_cast<int>(pixel.y()) / cell_;
  if (pixel.x() < 0.0 || pixel.y() < 0.0 || cx >= cols_ || cy >= rows_) return -1;
  return cy * cols_ + cx;
}

void DepthGrid::add(const Eigen::Vector2d& pixel, float z) {
  const int i = index(pixel);
  if (i < 0) return;
  Cell& c = cells_[static_cast<size_t>(i)];
  if (c.far_z < c.near_z) filled_.push_back(i);  // the first point in the cell
  if (z < c.near_z) c.near_z = z, c.near_u = static_cast<float>(pixel.x()), c.near_v = static_cast<float>(pixel.y());
  if (z > c.far_z) c.far_z = z, c.far_u = static_cast<float>(pixel.x()), c.far_v = static_cast<float>(pixel.y());
}

float DepthGrid::nearest(const Eigen::Vector2d& pixel) const {
  const int i = index(pixel);
  return i >= 0 ? cells_[static_cast<size_t>(i)].near_z : std::numeric_limits<float>::infinity();
}

bool DepthGrid::depthEdge(const Eigen::Vector2d& pixel, double z, double radius_px, double tolerance,
                          double tolerance_rel) const {
  const int x0 = std::max(0, static_cast<int>((pixel.x() - radius_px) / cell_));
  const int x1 = std::min(cols_ - 1, static_cast<int>((pixel.x() + radius_px) / cell_));
  const int y0 = std::max(0, static_cast<int>((pixel.y() - radius_px) / cell_));
  const int y1 = std::min(rows_ - 1, static_cast<int>((pixel.y() + radius_px) / cell_));
  // samples (du, dv, 1/z) relative to the point; the point itself is one
  constexpr int kMax = 128;
  double su[kMax], sv[kMax], sw[kMax];
  int n = 0;
  su[n] = 0.0, sv[n] = 0.0, sw[n] = 1.0 / z, ++n;
  const double r2 = radius_px * radius_px;
  auto take = [&](float zz, float u, float v) {
    const double du = u - pixel.x(), dv = v - pixel.y();
    if (n < kMax && du * du + dv * dv <= r2) su[n] = du, sv[n] = dv, sw[n] = 1.0 / zz, ++n;
  };
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const Cell& c = cells_[static_cast<size_t>(y) * cols_ + x];
      if (!std::isfinite(c.near_z)) continue;
      take(c.near_z, c.near_u, c.near_v);
      if (c.far_z > c.near_z) take(c.far_z, c.far_u, c.far_v);
    }
  if (n < 4) return false;  // too little known around the point to tell
  // least-squares plane w = a du + b dv + c
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d row(su[i], sv[i], 1.0);
    A += row * row.transpose();
    b += row * sw[i];
  }
  Eigen::Vector3d plane = A.ldlt().solve(b);
  if (!plane.allFinite()) plane = Eigen::Vector3d(0.0, 0.0, 1.0 / z);  // degenerate layout: a constant
  // a depth deviation dz at depth z is an inverse-depth deviation dz / z^2
  const double w = 1.0 / z, tol_w = (tolerance + tolerance_rel * z) * w * w;
  for (int i = 0; i < n; ++i)
    if (std::abs(plane.x() * su[i] + plane.y() * sv[i] + plane.z() - sw[i]) > tol_w) return true;
  return false;
}

CellGrid::CellGrid(int width, int height, int cell_px)
    : cell(std::max(8, cell_px)), cols((width + cell - 1) / cell), rows((height + cell - 1) / cell) {}

int chooseReference(const MapPoint& m, const Vec3& c_W, int64_t utime, const SelectionOptions& o) {
  const Vec3 ray = m.position - c_W;
  int best = -1;
  double best_score = std::numeric_limits<double>::infinity();
  for (size_t j = 0; j < m.observations.size(); ++j) {
    const PatchObservation& obs = m.observations[j];
    const double angle = angleBetweenDeg(ray, m.position - obs.cameraCentre());
    if (angle > o.max_view_angle_deg) continue;
    const double age = std::max(0.0, toSeconds(utime - obs.utime));
    const double score = o.view_angle_weight * angle + o.error_weight * obs.error + o.age_weight * age;
    if (score < best_score) {  // strict: the older of equal scores (deterministic)
      best_score = score;
      best = static_cast<int>(j);
    }
  }
  return best;
}

namespace {

// The point a grid cell tracks: the best textured of those whose reference fits.
struct Candidate {
  int point = -1, observation = -1;
  float gradient = -1.0f;
  Eigen::Matrix2d A;
  Eigen::Vector2d shift;  // level 0: the reference's projection through the calibration, from the patch centre
};

// The warp A of point m's reference observation `ref` into the view T_W_C and the shift of the
// reference's projection through `calibration` from the stored patch's centre; false if there is no
// reference (ref < 0), it does not project, or the warped patch leaves the stored one.
bool referenceWarp(const CameraProjection& camera, const Pose3& T_W_C, const SensorCalibration& calibration,
                   const MapPoint& m, int ref, Eigen::Matrix2d* A, Eigen::Vector2d* shift) {
  const double corner = 0.5 * (kPatch - 1), reach = 0.5 * (kStored - 1);
  Eigen::Vector2d u_ref;
  *shift = Eigen::Vector2d::Zero();
  bool ok = ref >= 0;
  if (ok) {
    // the reference view through the calibration in the state (reference_view.hpp)
    const ReferenceView& view = m.observations[static_cast<size_t>(ref)].view;
    ok = projectIntoReference(camera, view, calibration, m.position, &u_ref) &&
         affineWarp(camera, T_W_C, view.T_W_I * calibration.pose(), m.position, m.normal, A);
    *shift = u_ref - view.pixel;
  }
  // the warped 8x8 patch (with a pixel's room for the update to move it) must stay inside the
  // stored one at every level: check its corners
  const double max_shift = shift->cwiseAbs().maxCoeff();
  for (int k = 0; ok && k < 4; ++k) {
    const Eigen::Vector2d d((k & 1) ? corner : -corner, (k & 2) ? corner : -corner);
    ok = (*A * d).cwiseAbs().maxCoeff() + max_shift + 1.0 <= reach;
  }
  return ok;
}

// Per cell of `grid` the candidate among the map points in view, not occluded, off depth edges and
// with a reference that fits (counted in `st`).
std::vector<Candidate> candidatesPerCell(const PointPatchMap& map, const CameraProjection& camera, const Pose3& T_W_C,
                                         const SensorCalibration& calibration, int64_t utime, const DepthGrid& depth,
                                         int levels, const SelectionOptions& o, const CellGrid& grid,
                                         SelectionStats* st) {
  std::vector<Candidate> cells(grid.size());
  const Pose3 T_C_W = T_W_C.inverse();
  const Vec3 c_W = T_W_C.translation();
  const double border = patchBorder(levels);
  for (size_t i = 0; i < map.size(); ++i) {
    const MapPoint& m = map.point(static_cast<int>(i));
    const Vec3 p_C = T_C_W * m.position;
    if (p_C.z() < o.min_depth || p_C.z() > o.max_depth) continue;
    Eigen::Vector2d px;
    if (!camera.project(p_C, &px, border)) continue;
    ++st->in_view;
    if (depth.occluded(px, p_C.z(), o.occlusion_tolerance, o.occlusion_tolerance_rel)) {
      ++st->occluded;
      continue;
    }
    if (depth.depthEdge(px, p_C.z(), o.depth_edge_radius_px, o.depth_edge_tolerance, o.depth_edge_tolerance_rel)) {
      ++st->depth_edge;
      continue;
    }
    const int ref = chooseReference(m, c_W, utime, o);
    Eigen::Matrix2d A;
    Eigen::Vector2d shift;
    if (!referenceWarp(camera, T_W_C, calibration, m, ref, &A, &shift)) {
      ++st->no_reference;
      continue;
    }
    const PatchObservation& obs = m.observations[static_cast<size_t>(ref)];
    Candidate& c = cells[grid.of(px)];
    if (obs.gradient > c.gradient) {  // strict: the earlier (older) point of equal texture
      c.point = static_cast<int>(i);
      c.observation = ref;
      c.gradient = obs.gradient;
      c.A = A;
      c.shift = shift;
    }
  }
  return cells;
}

// The tracked patch of a candidate: its reference warped into this view at every level; false if the
// warp leaves the stored patch.
bool trackPatch(const PointPatchMap& map, const Candidate& c, float exposure_time, int levels, TrackedPatch* t) {
  const MapPoint& m = map.point(c.point);
  const PatchObservation& obs = m.observations[static_cast<size_t>(c.observation)];
  t->point = c.point;
  t->observation = c.observation;
  t->p_W = m.position;
  t->gradient = c.gradient;
  t->view = obs.view;
  t->reference_cov_W = obs.pose_cov_W.cast<double>();
  t->gain0 = exposure_time > 0.0f && obs.exposure_time > 0.0f ? exposure_time / obs.exposure_time : 1.0f;
  t->shift0 = c.shift;
  t->warp = c.A;
  bool ok = true;
  for (int l = 0; l < levels && ok; ++l) {
    const size_t at = static_cast<size_t>(l) * kPatchArea;
    ok = warpReferencePatch(obs.level(l), c.A, c.shift / static_cast<double>(1 << l), t->reference.data() + at,
                            t->reference_dx.data() + at, t->reference_dy.data() + at);
  }
  return ok;
}

}  // namespace

std::vector<TrackedPatch> selectPatches(const PointPatchMap& map, const CameraProjection& camera, const Pose3& T_W_C,
                                        const SensorCalibration& calibration, int64_t utime, float exposure_time,
                                        const DepthGrid& depth, int levels, const SelectionOptions& o,
                                        SelectionStats* stats) {
  SelectionStats st;
  const CellGrid grid(camera.rig().width, camera.rig().height, o.grid_cell_px);
  const std::vector<Candidate> cells =
      candidatesPerCell(map, camera, T_W_C, calibration, utime, depth, levels, o, grid, &st);
  std::vector<TrackedPatch> out;
  out.reserve(
      static_cast<size_t>(std::count_if(cells.begin(), cells.end(), [](const Candidate& c) { return c.point >= 0; })));
  for (const Candidate& c : cells) {
    if (c.point < 0) continue;
    TrackedPatch& t = out.emplace_back();  // filled in place: a TrackedPatch is over 1 kB
    if (!trackPatch(map, c, exposure_time, levels, &t)) {
      out.pop_back();
      ++st.no_reference;
    }
  }
  st.selected = static_cast<int>(out.size());
  if (stats) *stats = st;
  return out;
}

}  // namespace livo::vio
