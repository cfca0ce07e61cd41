#include "livo/evaluate/umeyama.hpp"

#include <Eigen/SVD>
#include <limits>
#include <string>

namespace livo::evaluate {

Pose3 Similarity3::apply(const Pose3& T) const {
  Pose3 out = Pose3::Identity();
  out.linear() = rotation * T.linear();
  out.translation() = apply(Vec3(T.translation()));
  return out;
}

Eigen::Matrix4d Similarity3::matrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = scale * rotation;
  m.topRightCorner<3, 1>() = translation;
  return m;
}

PairedCentroids pairedCentroids(const std::vector<Vec3>& source, const std::vector<Vec3>& target) {
  if (source.size() != target.size())
    throw AlignmentError("alignment needs as many source as target points (" + std::to_string(source.size()) + " vs " +
                         std::to_string(target.size()) + ")");
  if (source.empty()) throw AlignmentError("alignment needs at least one pair of points");
  PairedCentroids c;
  for (size_t i = 0; i < source.size(); ++i) {
    c.source += source[i];
    c.target += target[i];
  }
  c.source /= static_cast<double>(source.size());
  c.target /= static_cast<double>(source.size());
  return c;
}

Similarity3 umeyamaAlignment(const std::vector<Vec3>& source, const std::vector<Vec3>& target, bool with_scale) {
  const double n = static_cast<double>(source.size());
  const PairedCentroids centroids = pairedCentroids(source, target);
  const Vec3 &mean_x = centroids.source, &mean_y = centroids.target;

  double sigma_x = 0.0;     // variance of the source, eq. 36
  Mat3 cov = Mat3::Zero();  // cross-covariance, eq. 38
  for (size_t i = 0; i < source.size(); ++i) {
    const Vec3 dx = source[i] - mean_x;
    sigma_x += dx.squaredNorm();
    cov += (target[i] - mean_y) * dx.transpose();
  }
  sigma_x /= n;
  cov *= 1.0 / n;

  const Eigen::JacobiSVD<Mat3> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3 d = svd.singularValues();
  int rank = 0;
  for (int i = 0; i < 3; ++i) rank += d[i] > std::numeric_limits<double>::epsilon() ? 1 : 0;
  if (rank < 2)
    throw AlignmentError("cannot align: the " + std::to_string(source.size()) +
                         " associated positions lie on a line or a point (cross-covariance rank " +
                         std::to_string(rank) + ")");

  Mat3 S = Mat3::Identity();  // eq. 43: keep a right-handed rotation
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;

  Similarity3 sim;
  sim.rotation = svd.matrixU() * S * svd.matrixV().transpose();           // eq. 40
  sim.scale = with_scale ? (d.asDiagonal() * S).trace() / sigma_x : 1.0;  // eq. 42
  sim.translation = mean_y - sim.scale * (sim.rotation * mean_x);         // eq. 41
  return sim;
}

}  // namespace livo::evaluate
