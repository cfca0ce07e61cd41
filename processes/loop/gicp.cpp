#include "gicp.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace livo::loop {

GicpCloud GicpCloud::build(Points points, int num_neighbors, double plane_epsilon) {
  GicpCloud c;
  c.cloud = std::make_shared<const Points>(std::move(points));
  c.tree = std::make_shared<const PointTree>(*c.cloud);
  c.covariances = estimateCovariances(*c.cloud, *c.tree, num_neighbors, plane_epsilon);
  return c;
}

GicpCloud GicpCloud::fromParts(Points points, Covariances covariances) {
  GicpCloud c;
  c.cloud = std::make_shared<const Points>(std::move(points));
  c.covariances = std::move(covariances);
  c.tree = std::make_shared<const PointTree>(*c.cloud);
  return c;
}

namespace {
struct Linearisation {
  Mat6 H = Mat6::Zero();
  Vec6 b = Vec6::Zero();
  double sum_sq = 0.0;
  int count = 0;
};

// Left perturbation: T' = [Exp(dr), dt] * T, so p' = p + dr x p + dt for p = T s.
Linearisation linearise(const GicpCloud& source, const GicpCloud& target, const Pose3& T, double max_d2) {
  Linearisation L;
  const Mat3 R = T.linear();
  for (size_t i = 0; i < source.size(); ++i) {
    const Vec3 p = T * source.points()[i];
    size_t j;
    double d2;
    if (!target.tree->nearest(p, j, d2) || d2 > max_d2) continue;
    const Vec3 e = target.points()[j] - p;  // residual
    const Mat3 C = target.covariances[j] + R * source.covariances[i] * R.transpose();
    const Mat3 M = C.inverse();
    Eigen::Matrix<double, 3, 6> J;  // d e / d [dr; dt]
    J.leftCols<3>() = so3::hat(p);
    J.rightCols<3>() = -Mat3::Identity();
    const Eigen::Matrix<double, 6, 3> JtM = J.transpose() * M;
    L.H += JtM * J;
    L.b += JtM * e;
    L.sum_sq += d2;
    ++L.count;
  }
  return L;
}
}  // namespace

GicpResult gicpRegister(const GicpCloud& source, const GicpCloud& target, const Pose3& initial,
                        const GicpOptions& options) {
  GicpResult r;
  r.T_target_source = initial;
  if (source.size() == 0 || target.size() == 0) return r;
  const double max_d2 = options.max_correspondence_distance * options.max_correspondence_distance;
  Pose3 T = initial;
  for (int it = 0; it < options.max_iterations; ++it) {
    const Linearisation L = linearise(source, target, T, max_d2);
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
  r.T_target_source = T;
  const Linearisation L = linearise(source, target, T, max_d2);
  r.num_correspondences = L.count;
  r.fitness = L.count > 0 ? L.sum_sq / L.count : 0.0;
  r.information = L.H;
  if (L.count > 0) {
    Eigen::SelfAdjointEigenSolver<Mat3> es(L.H.bottomRightCorner<3, 3>() / L.count);
    r.min_translation_eigenvalue = es.eigenvalues()[0];
    if (es.eigenvalues()[2] > 0.0) r.translation_eigenvalue_ratio = es.eigenvalues()[0] / es.eigenvalues()[2];
  }
  const double od2 = options.overlap_distance * options.overlap_distance;
  int overlapping = 0;
  for (const Vec3& s : source.points()) {
    size_t j;
    double d2;
    if (target.tree->nearest(T * s, j, d2) && d2 <= od2) ++overlapping;
  }
  r.overlap = static_cast<double>(overlapping) / static_cast<double>(source.size());
  return r;
}

}  // namespace livo::loop
