#include "livo/loop/gicp.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace livo::loop {

CompactCovariance::CompactCovariance(const Mat3& m)
    : c_{static_cast<float>(m(0, 0)), static_cast<float>(m(0, 1)), static_cast<float>(m(0, 2)),
         static_cast<float>(m(1, 1)), static_cast<float>(m(1, 2)), static_cast<float>(m(2, 2))} {}

Mat3 CompactCovariance::matrix() const {
  Mat3 m;
  m << c_[0], c_[1], c_[2], c_[1], c_[3], c_[4], c_[2], c_[4], c_[5];
  return m;
}

GicpCloud GicpCloud::build(Points points, int num_neighbors, double plane_epsilon) {
  GicpCloud c;
  c.cloud = std::make_shared<const Points>(std::move(points));
  c.tree = std::make_shared<const PointTree>(*c.cloud);
  const Covariances full = estimateCovariances(*c.cloud, *c.tree, num_neighbors, plane_epsilon);
  c.covariances.reserve(full.size());
  for (const Mat3& m : full) c.covariances.emplace_back(m);
  return c;
}

namespace {
struct Linearisation {
  Mat6 H = Mat6::Zero();
  Vec6 b = Vec6::Zero();
  double sum_sq = 0.0;
  int count = 0;        // correspondences within the maximum distance
  int overlapping = 0;  // of them, within the overlap distance
};

// Left perturbation: T' = [Exp(dr), dt] * T, so p' = p + dr x p + dt for p = T s. One nearest-
// neighbour search per source point, bounded by the correspondence distance.
Linearisation linearise(const GicpCloud& source, const GicpCloud& target, const Pose3& T, double max_d2,
                        double overlap_d2, size_t stride) {
  Linearisation L;
  const Mat3 R = T.linear();
  for (size_t i = 0; i < source.size(); i += stride) {
    const Vec3 p = T * source.points()[i];
    size_t j;
    double d2;
    if (!target.tree->nearestWithin(p, max_d2, j, d2)) continue;
    const Vec3 e = target.points()[j] - p;  // residual
    const Mat3 C = target.covariances[j].matrix() + R * source.covariances[i].matrix() * R.transpose();
    const Mat3 M = C.inverse();
    Eigen::Matrix<double, 3, 6> J;  // d e / d [dr; dt]
    J.leftCols<3>() = so3::hat(p);
    J.rightCols<3>() = -Mat3::Identity();
    const Eigen::Matrix<double, 6, 3> JtM = J.transpose() * M;
    L.H += JtM * J;
    L.b += JtM * e;
    L.sum_sq += d2;
    ++L.count;
    L.overlapping += d2 <= overlap_d2;
  }
  return L;
}

// The point-to-plane part of the cost at T (one more pass over the source): the normal of each
// pair's summed covariance, the Jacobian of the residual along it, and the residual's variance.
void planeInformation(const GicpCloud& source, const GicpCloud& target, const Pose3& T, double max_d2, size_t stride,
                      GicpResult& r) {
  const Mat3 R = T.linear();
  Mat6 H = Mat6::Zero();
  double sum_sq = 0.0;
  int count = 0;
  for (size_t i = 0; i < source.size(); i += stride) {
    const Vec3 p = T * source.points()[i];
    size_t j;
    double d2;
    if (!target.tree->nearestWithin(p, max_d2, j, d2)) continue;
    const Mat3 C = target.covariances[j].matrix() + R * source.covariances[i].matrix() * R.transpose();
    Eigen::SelfAdjointEigenSolver<Mat3> es;
    es.compute(C);
    const Vec3 n = es.eigenvectors().col(0);
    Eigen::Matrix<double, 1, 6> Jn;  // d (n . e) / d [dr; dt], e = t - p
    Jn.leftCols<3>() = n.transpose() * so3::hat(p);
    Jn.rightCols<3>() = -n.transpose();
    H += Jn.transpose() * Jn;
    const double en = n.dot(target.points()[j] - p);
    sum_sq += en * en;
    ++count;
  }
  if (count <= 6 || sum_sq <= 0.0) return;
  r.plane_residual_variance = sum_sq / (count - 6);
  r.plane_correspondences = count;
  r.plane_information = H / r.plane_residual_variance;
}
}  // namespace

GicpResult gicpRegister(const GicpCloud& source, const GicpCloud& target, const Pose3& initial,
                        const GicpOptions& options) {
  GicpResult r;
  r.T_target_source = initial;
  if (source.size() == 0 || target.size() == 0) return r;
  const double max_d2 = options.max_correspondence_distance * options.max_correspondence_distance;
  const double overlap_d2 = std::min(options.overlap_distance * options.overlap_distance, max_d2);
  // Every stride-th source point (the cloud is in voxel order, so this thins it evenly).
  const size_t stride = options.max_source_points > 0 ? (source.size() + options.max_source_points - 1) /
                                                            static_cast<size_t>(options.max_source_points)
                                                      : 1;
  const size_t used = (source.size() + stride - 1) / stride;
  Pose3 T = initial;
  Linearisation L;
  for (int it = 0; it < options.max_iterations; ++it) {
    L = linearise(source, target, T, max_d2, overlap_d2, stride);
    r.iterations = it + 1;
    if (L.count < 6) return r;
    const Vec6 dx = L.H.ldlt().solve(-L.b);
    if (!dx.allFinite()) return r;
    Pose3 D = Pose3::Identity();
    D.linear() = so3::Exp(dx.head<3>());
    D.translation() = dx.tail<3>();
    T = D * T;
    T.linear() = so3::normalize(T.linear());
    if (dx.head<3>().norm() < options.rotation_epsilon && dx.tail<3>().norm() < options.translation_epsilon) {
      r.converged = true;
      break;
    }
  }
  // The scores come from the last linearisation, before its (converged: negligible) final step,
  // rather than from one more pass over the source.
  r.T_target_source = T;
  r.num_correspondences = L.count;
  r.fitness = L.count > 0 ? L.sum_sq / L.count : 0.0;
  r.information = L.H;
  r.overlap = static_cast<double>(L.overlapping) / static_cast<double>(used);
  if (r.converged) planeInformation(source, target, T, max_d2, stride, r);
  if (L.count > 0) {
    Eigen::SelfAdjointEigenSolver<Mat3> es(L.H.bottomRightCorner<3, 3>() / L.count);
    r.min_translation_eigenvalue = es.eigenvalues()[0];
    if (es.eigenvalues()[2] > 0.0) r.translation_eigenvalue_ratio = es.eigenvalues()[0] / es.eigenvalues()[2];
  }
  return r;
}

}  // namespace livo::loop
