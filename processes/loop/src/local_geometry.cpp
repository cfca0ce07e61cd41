#include "livo/loop/local_geometry.hpp"

#include <Eigen/Eigenvalues>

namespace livo::loop {

namespace {
Mat3 sampleCovariance(const Points& points, const size_t* idx, size_t n, Vec3& mean) {
  mean.setZero();
  for (size_t i = 0; i < n; ++i) mean += points[idx[i]];
  mean /= static_cast<double>(n);
  Mat3 c = Mat3::Zero();
  for (size_t i = 0; i < n; ++i) {
    const Vec3 d = points[idx[i]] - mean;
    c += d * d.transpose();
  }
  return c / static_cast<double>(n);
}
}  // namespace

std::vector<Neighbourhood> analyseNeighbourhoods(const Points& points, const PointTree& tree, double radius,
                                                 const Vec3& viewpoint) {
  std::vector<Neighbourhood> out(points.size());
  std::vector<std::pair<size_t, double>> nb;
  std::vector<size_t> idx;
  for (size_t i = 0; i < points.size(); ++i) {
    tree.radius(points[i], radius, nb, false);
    Neighbourhood& h = out[i];
    h.count = static_cast<int>(nb.size());
    if (nb.size() < 3) continue;
    idx.resize(nb.size());
    for (size_t k = 0; k < nb.size(); ++k) idx[k] = nb[k].first;
    Vec3 mean;
    const Mat3 c = sampleCovariance(points, idx.data(), idx.size(), mean);
    Eigen::SelfAdjointEigenSolver<Mat3> es(c);
    h.eigenvalues = es.eigenvalues();
    h.normal = es.eigenvectors().col(0);
    if (h.normal.dot(viewpoint - points[i]) < 0.0) h.normal = -h.normal;
  }
  return out;
}

Covariances estimateCovariances(const Points& points, const PointTree& tree, int num_neighbors, double plane_epsilon) {
  Covariances covs(points.size(), Mat3::Identity());
  const size_t k = static_cast<size_t>(std::max(num_neighbors, 3));
  std::vector<size_t> idx(k);
  std::vector<double> d2(k);
  const Vec3 values(plane_epsilon, 1.0, 1.0);
  for (size_t i = 0; i < points.size(); ++i) {
    const size_t n = tree.knn(points[i], k, idx.data(), d2.data());
    if (n < 3) continue;
    Vec3 mean;
    const Mat3 c = sampleCovariance(points, idx.data(), n, mean);
    Eigen::SelfAdjointEigenSolver<Mat3> es(c);
    const Mat3& V = es.eigenvectors();  // ascending eigenvalues: column 0 is the normal
    covs[i] = V * values.asDiagonal() * V.transpose();
  }
  return covs;
}

}  // namespace livo::loop
