#include "livo/lio_graph/scan_matching.hpp"

#include <cmath>

#include <Eigen/Eigenvalues>

#include "livo/plane.hpp"

namespace livo::lio_graph {

void LocalMap::rebuild(std::vector<Vec3> edges, std::vector<Vec3> surfaces) {
  edge_tree_.reset();
  surface_tree_.reset();
  edges_ = std::move(edges);
  surfaces_ = std::move(surfaces);
  edge_tree_ = std::make_unique<KdTree<Vec3>>(edges_);
  surface_tree_ = std::make_unique<KdTree<Vec3>>(surfaces_);
}

namespace {

/// One linearised residual: r = n^T (p_w - q) with unit normal n.
struct Residual {
  Vec3 normal;
  Vec3 anchor;  // a point on the line or plane
  Vec3 body;    // the feature point, body frame
  double weight;
};

/// The nearest neighbours of q in `tree`, if all lie within max_distance.
bool neighbours(const KdTree<Vec3>& tree, const std::vector<Vec3>& data, const Vec3& q, int k, double max_distance,
                std::vector<Vec3>* out) {
  size_t idx[16];
  double d2[16];
  const size_t want = static_cast<size_t>(std::min(k, 16));
  const size_t n = tree.knn(q, want, idx, d2);
  if (n < want || d2[n - 1] > max_distance * max_distance) return false;
  out->resize(n);
  for (size_t i = 0; i < n; ++i) (*out)[i] = data[idx[i]];
  return true;
}

/// LIO-SAM's residual weight: large residuals far from the sensor count less; 0 drops it.
double residualWeight(double residual, const Vec3& body) {
  const double s = 1.0 - 0.9 * std::abs(residual) / std::sqrt(std::max(body.norm(), 1e-3));
  return s > 0.1 ? s : 0.0;
}

/// The plane of a surface point's map neighbours, if they make one (ScanMatchingOptions).
bool planeOf(const std::vector<Vec3>& nb, const ScanMatchingOptions& o, Plane* plane) {
  const int n = static_cast<int>(nb.size());
  if (o.min_planarity > 0.0) return fitPlane(nb.data(), n, o.max_plane_distance, plane, o.min_planarity);
  PlaneFit fit;
  if (!fitPlane(nb.data(), n, &fit)) return false;
  for (const Vec3& p : nb)
    if (!(std::abs(fit.plane.distance(p)) <= o.max_plane_distance)) return false;
  *plane = fit.plane;
  return true;
}

void collectResiduals(const LocalMap& map, const ScanFeatures& f, const Pose3& T, const ScanMatchingOptions& o,
                      std::vector<Residual>* out, int* edges, int* surfaces) {
  out->clear();
  *edges = *surfaces = 0;
  std::vector<Vec3> nb;
  if (map.edgeTree() && !map.edges().empty()) {
    for (const Vec3& b : f.edges) {
      const Vec3 w = T * b;
      if (!neighbours(*map.edgeTree(), map.edges(), w, o.neighbours, o.max_neighbour_distance, &nb)) continue;
      Vec3 c = Vec3::Zero();
      for (const Vec3& p : nb) c += p;
      c /= static_cast<double>(nb.size());
      Mat3 cov = Mat3::Zero();
      for (const Vec3& p : nb) cov += (p - c) * (p - c).transpose();
      const Eigen::SelfAdjointEigenSolver<Mat3> es(cov);
      if (!(es.eigenvalues()(2) > o.min_line_ratio * es.eigenvalues()(1))) continue;
      const Vec3 u = es.eigenvectors().col(2);
      const Vec3 perp = (w - c) - (w - c).dot(u) * u;
      const double d = perp.norm();
      if (!(d > 1e-6)) continue;
      const double s = residualWeight(d, b);
      if (s <= 0.0) continue;
      out->push_back({perp / d, c, b, s});
      ++*edges;
    }
  }
  if (map.surfaceTree() && !map.surfaces().empty()) {
    for (const Vec3& b : f.surfaces) {
      const Vec3 w = T * b;
      if (!neighbours(*map.surfaceTree(), map.surfaces(), w, o.neighbours, o.max_neighbour_distance, &nb)) continue;
      Plane plane;
      if (!planeOf(nb, o, &plane)) continue;
      const double d = plane.distance(w);
      const double s = residualWeight(d, b);
      if (s <= 0.0) continue;
      out->push_back({plane.normal, w - d * plane.normal, b, s});
      ++*surfaces;
    }
  }
}

}  // namespace

ScanMatchResult matchScan(const LocalMap& map, const ScanFeatures& features, const Pose3& initial,
                          const ScanMatchingOptions& o) {
  ScanMatchResult res;
  Mat3 R = initial.linear();
  Vec3 t = initial.translation();
  std::vector<Residual> residuals;
  Mat6 projection = Mat6::Identity();  // onto the constrained directions (fixed at the first iterate)
  for (int it = 0; it < o.max_iterations; ++it) {
    const Pose3 T = se3::fromRotationTranslation(R, t);
    collectResiduals(map, features, T, o, &residuals, &res.edge_residuals, &res.surface_residuals);
    res.iterations = it + 1;
    if (static_cast<int>(residuals.size()) < o.min_residuals) return res;
    Mat6 H = Mat6::Zero();
    Vec6 g = Vec6::Zero();
    for (const Residual& r : residuals) {
      const Vec3 pw = R * r.body + t;
      const double e = r.normal.dot(pw - r.anchor);
      Eigen::Matrix<double, 1, 6> J;
      J.head<3>() = -r.normal.transpose() * R * so3::hat(r.body);
      J.tail<3>() = r.normal.transpose();
      const double w2 = r.weight * r.weight;
      H += w2 * J.transpose() * J;
      g += w2 * J.transpose() * e;
    }
    res.hessian = H;
    if (it == 0) {
      const Eigen::SelfAdjointEigenSolver<Mat6> es(H);
      res.eigenvalues = es.eigenvalues();
      res.weakest = es.eigenvectors().col(0);
      Mat6 V = es.eigenvectors();
      Eigen::Matrix<double, 6, 6> keep = Mat6::Zero();
      for (int i = 0; i < 6; ++i) {
        if (es.eigenvalues()(i) < o.degenerate_eigenvalue) {
          res.degenerate = true;
        } else {
          keep(i, i) = 1.0;
        }
      }
      projection = V * keep * V.transpose();
    }
    // the step within the constrained directions only: (P H P + (I - P)) delta = -P g
    const Mat6 H_c = projection * H * projection + (Mat6::Identity() - projection);
    const Vec6 delta = projection * H_c.ldlt().solve(-(projection * g));
    if (!delta.allFinite()) return res;
    R = R * so3::Exp(Vec3(delta.head<3>()));
    t += delta.tail<3>();
    if (delta.head<3>().norm() < o.converged_rotation && delta.tail<3>().norm() < o.converged_translation) {
      res.converged = true;
      break;
    }
  }
  res.T_W_I = se3::fromRotationTranslation(so3::normalize(R), t);
  res.valid = res.T_W_I.matrix().allFinite();
  return res;
}

}  // namespace livo::lio_graph
