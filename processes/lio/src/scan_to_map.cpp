#include "livo/lio/scan_to_map.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace livo::lio {

ScanToMapOptions matchingForRangeNoise(double range_noise_std, const ScanToMapOptions& base) {
  constexpr double kTunedNoise = 0.01;  // m, the range noise the defaults were tuned at
  ScanToMapOptions o = base;
  const double sigma = range_noise_std;
  if (!(sigma > kTunedNoise)) return o;
  const double growth = std::min(1.0, (sigma - kTunedNoise) / (2.0 * kTunedNoise));  // 0 at 1 cm, 1 from 3 cm
  o.plane.num_neighbors = base.plane.num_neighbors + static_cast<int>(std::lround(3.0 * growth));
  o.plane.max_plane_thickness = std::max(base.plane.max_plane_thickness, 2.0 * sigma);
  // the model error of the tuning (curvature, discretisation), as large as the planes it accepts are thick
  const double tuned_k = base.plane.num_neighbors;
  const double tuned_floor2 =
      std::max(0.0, base.point_noise_std * base.point_noise_std - (1.0 + 1.0 / tuned_k) * kTunedNoise * kTunedNoise);
  const double thicker = o.plane.max_plane_thickness / base.plane.max_plane_thickness;
  o.point_noise_std = std::max(base.point_noise_std, std::sqrt(thicker * thicker * tuned_floor2 +
                                                               (1.0 + 1.0 / o.plane.num_neighbors) * sigma * sigma));
  return o;
}

namespace {
// Fewer searches than this per thread are not worth waking another thread for (a search and its
// plane fit take about a microsecond; a wake-up tens of them).
constexpr size_t kMinSearchesPerThread = 256;
}  // namespace

ScanToMap::ScanToMap(const VoxelMap& map, const VoxelPlanes* planes, const std::vector<Vec3>& body_points,
                     const ScanToMapOptions& options, WorkerThreads* threads, const SensorCalibration& undistorted_with,
                     const Vec3& body_rate)
    : map_(map),
      planes_(planes),
      points_(body_points.size()),
      body_rate_(body_rate),
      undistorted_dt_(undistorted_with.dt),
      options_(options),
      threads_(threads),
      matches_(body_points.size()),
      gate_(body_points.size()),
      world_(body_points.size()) {
  const Mat3 R_LI = undistorted_with.rot.transpose();
  for (size_t i = 0; i < points_.size(); ++i) {
    points_[i] = R_LI * (body_points[i] - undistorted_with.pos);
    gate_[i] = options_.residual_range_factor * std::sqrt(body_points[i].norm());
  }
  floor_.diagonal().head<3>().setConstant(options_.registration_floor_rotation * options_.registration_floor_rotation);
  floor_.diagonal().segment<3>(3).setConstant(options_.registration_floor_translation *
                                              options_.registration_floor_translation);
}

int ScanToMap::numMatched() const {
  int n = 0;
  for (const auto& m : matches_) n += m.has_plane ? 1 : 0;
  return n;
}

std::vector<uint32_t> ScanToMap::placePoints(const Mat3& R_WL, const Vec3& t_WL, int iteration) {
  const double research2 = options_.research_distance * options_.research_distance;
  std::vector<uint32_t> to_search;
  for (size_t i = 0; i < points_.size(); ++i) {
    world_[i] = R_WL * points_[i] + t_WL;
    if (iteration == 0 || !((world_[i] - matches_[i].searched_at).squaredNorm() <= research2))
      to_search.push_back(static_cast<uint32_t>(i));
  }
  return to_search;
}

void ScanToMap::fitPlanes(const std::vector<uint32_t>& to_search) {
  const int k = options_.plane.num_neighbors;
  auto search = [&](size_t begin, size_t end) {
    Vec3 nb[32];
    double d2[32];
    for (size_t j = begin; j < end; ++j) {
      const uint32_t i = to_search[j];
      Match& m = matches_[i];
      m.searched_at = world_[i];
      if (const Plane* voxel_plane = planes_ ? planes_->planeAt(world_[i]) : nullptr) {
        m.plane = *voxel_plane;
        m.has_plane = m.observes_normal = true;
        continue;
      }
      m.has_plane = map_.knn(world_[i], k, options_.plane.max_neighbor_distance, nb, d2) == k &&
                    fitPlane(nb, k, options_.plane.max_plane_thickness, &m.plane, options_.plane.min_planarity,
                             &m.observes_normal);
    }
  };
  if (threads_)
    threads_->forEachShare(to_search.size(), search, kMinSearchesPerThread);
  else
    search(0, to_search.size());
}

std::vector<ScanToMap::Row> ScanToMap::residualRows(const FilterState& x, const Pose3& sweep_end) const {
  std::vector<Row> rows;
  for (size_t i = 0; i < points_.size(); ++i) {
    const Match& m = matches_[i];
    if (!m.has_plane) continue;
    const double r = m.plane.distance(world_[i]);
    if (!(std::abs(r) <= gate_[i])) continue;
    rows.push_back(
        Row{PointToPlaneResidual{points_[i], m.plane}.jacobian(x, sweep_end, body_rate_), r, m.observes_normal});
  }
  return rows;
}

double ScanToMap::robustScale2(const std::vector<Row>& rows) const {
  // Cauchy weights with a scale that follows the residuals while the iterate is still far off
  // (3 robust standard deviations) and settles at robust_scale near the optimum.
  if (!(options_.robust_scale > 0.0)) return 0.0;
  std::vector<double> abs_r(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) abs_r[i] = std::abs(rows[i].r);
  auto mid = abs_r.begin() + static_cast<std::ptrdiff_t>(abs_r.size() / 2);
  std::nth_element(abs_r.begin(), mid, abs_r.end());
  const double c = std::max(options_.robust_scale, 3.0 * 1.4826 * *mid);
  return c * c;
}

Mat6 ScanToMap::degeneracyGeometry(const std::vector<Row>& rows) const {
  // The degeneracy test counts only the rows whose planes stay planes with any one neighbour left
  // out: a line of floor points plus the wall point beside it spans a plane that point chose, and
  // in a corridor such planes are the only rows along the axis, hiding its degeneracy.
  const double inv_lever = 1.0 / options_.degeneracy_lever_arm;
  Mat6 G = Mat6::Zero();
  int observing = 0;
  for (const Row& row : rows) {
    if (!row.observes_normal) continue;
    Row6 hs = row.h.head<6>();
    hs.head<3>() *= inv_lever;
    G.noalias() += hs.transpose() * hs;
    ++observing;
  }
  return G / static_cast<double>(std::max(observing, 1));
}

void ScanToMap::information(const std::vector<Row>& rows, double c2, bool degenerate, Mat13* S, Vec13* g) const {
  const double w = 1.0 / (options_.point_noise_std * options_.point_noise_std);
  *S = Mat13::Zero();
  *g = Vec13::Zero();
  for (const Row& row : rows) {
    if (degenerate && !row.observes_normal) continue;
    const double rw = c2 > 0.0 ? 1.0 / (1.0 + row.r * row.r / c2) : 1.0;
    S->noalias() += rw * row.h.transpose() * row.h;
    g->noalias() += rw * row.h.transpose() * row.r;
  }
  *S *= w;
  *g *= w;
}

bool ScanToMap::evaluate(const FilterState& x, int iteration, MeasurementInformation* info) {
  // the body pose at the sweep's true end and the LiDAR's mounting at the iterate
  const Pose3 sweep_end = sweepEndPose(x, body_rate_, undistorted_dt_);
  const Mat3 R_WL = sweep_end.linear() * x.lidar.rot;
  const Vec3 t_WL = sweep_end * x.lidar.pos;
  // 1. the points' images, and which of them moved enough to search their neighbours anew
  const std::vector<uint32_t> to_search = placePoints(R_WL, t_WL, iteration);
  // 2. the searches and plane fits: each point's own, so they may run on several threads
  fitPlanes(to_search);
  // 3. the residuals, in the points' order (the sums below do not depend on the threads)
  const std::vector<Row> rows = residualRows(x, sweep_end);
  const int count = static_cast<int>(rows.size());
  last_count_ = count;
  info->count = count;
  if (count == 0) return false;

  const double c2 = robustScale2(rows);
  info->geometry = degeneracyGeometry(rows);
  degeneracy_ = analyzeDegeneracy(info->geometry, options_.degeneracy_threshold);
  // Where the other rows fix the whole pose, such a plane is mostly right (four points of one
  // ring on a wall and one of the next look the same) and a wrong one is outvoted; where they do
  // not, it would be the only say in a direction, and a wrong one tilts the attitude there.
  const bool degenerate = options_.remove_degenerate && degeneracy_.degenerate;
  Mat13 S;
  Vec13 g;
  information(rows, c2, degenerate, &S, &g);
  info->calibration_block = FilterState::kLidar;
  min_information_eigenvalue_ =
      Eigen::SelfAdjointEigenSolver<Mat6>(Mat6(S.topLeftCorner<6, 6>()), Eigen::EigenvaluesOnly).eigenvalues()[0];
  if (degenerate) {
    // the pose off its degenerate directions; the calibration, which the same rows would measure
    // along them (the extrinsic translation's column is the position's), not at all
    Mat6 Sp = S.topLeftCorner<6, 6>();
    Vec6 gp = g.head<6>();
    removeDegenerateInformation(degeneracy_, &Sp, &gp);
    S.setZero();
    g.setZero();
    S.topLeftCorner<6, 6>() = Sp;
    g.head<6>() = gp;
  }
  if (options_.registration_floor_rotation > 0.0 || options_.registration_floor_translation > 0.0)
    applyMeasurementFloor(floor_, &S, &g);
  info->HtRinvH = S;
  info->HtRinvz = g;
  return true;
}

}  // namespace livo::lio
