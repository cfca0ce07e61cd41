#include "fpfh.hpp"

#include <cmath>

namespace livo::loop {

namespace {
constexpr int kBins = 11;

// Darboux-frame angles of the pair (p1, n1) -> (p2, n2), with the source chosen as the point
// whose normal makes the smaller angle with the connecting line. False if degenerate.
bool pairAngles(const Vec3& p1, const Vec3& n1, const Vec3& p2, const Vec3& n2, double& alpha, double& phi,
                double& theta) {
  Vec3 d = p2 - p1;
  const double len = d.norm();
  if (len <= 0.0) return false;
  d /= len;
  const double c1 = n1.dot(d);
  const double c2 = n2.dot(d);
  Vec3 u = n1, nt = n2;
  phi = c1;
  if (std::abs(c1) < std::abs(c2)) {  // the angle at p1 is larger: use p2 as the source
    u = n2;
    nt = n1;
    d = -d;
    phi = -c2;
  }
  Vec3 v = d.cross(u);
  const double vn = v.norm();
  if (vn <= 1e-12) return false;
  v /= vn;
  const Vec3 w = u.cross(v);
  alpha = v.dot(nt);
  theta = std::atan2(w.dot(nt), u.dot(nt));
  return true;
}

int bin(double value, double lo, double hi) {
  const int b = static_cast<int>(std::floor((value - lo) / (hi - lo) * kBins));
  return std::min(std::max(b, 0), kBins - 1);
}
}  // namespace

Features computeFpfh(const Points& points, const Points& normals, const PointTree& tree, double radius) {
  const size_t n = points.size();
  Features spfh(n, Fpfh::Zero());
  std::vector<std::vector<std::pair<size_t, double>>> neighbours(n);
  for (size_t i = 0; i < n; ++i) {
    if (normals[i].isZero()) continue;
    tree.radius(points[i], radius, neighbours[i]);
    int count = 0;
    Fpfh h = Fpfh::Zero();
    for (const auto& [j, d2] : neighbours[i]) {
      if (j == i || normals[j].isZero()) continue;
      double alpha, phi, theta;
      if (!pairAngles(points[i], normals[i], points[j], normals[j], alpha, phi, theta)) continue;
      h[bin(theta, -M_PI, M_PI)] += 1.0f;
      h[kBins + bin(alpha, -1.0, 1.0)] += 1.0f;
      h[2 * kBins + bin(phi, -1.0, 1.0)] += 1.0f;
      ++count;
    }
    if (count > 0) spfh[i] = h * (100.0f / static_cast<float>(count));
  }
  Features out(n, Fpfh::Zero());
  for (size_t i = 0; i < n; ++i) {
    if (spfh[i].isZero()) continue;
    Fpfh acc = Fpfh::Zero();
    for (const auto& [j, d2] : neighbours[i]) {
      if (j == i || spfh[j].isZero() || d2 <= 0.0) continue;
      acc += spfh[j] * static_cast<float>(1.0 / std::sqrt(d2));
    }
    // Normalise each sub-histogram of the weighted sum to 100, then add the point's own SPFH.
    for (int s = 0; s < 3; ++s) {
      const float sum = acc.segment<kBins>(s * kBins).sum();
      if (sum > 0.0f) acc.segment<kBins>(s * kBins) *= 100.0f / sum;
    }
    out[i] = spfh[i] + acc;
  }
  return out;
}

Features computeFpfh(const Points& points, const FpfhOptions& options) {
  const PointTree tree(points);
  const Points normals = estimateNormals(points, tree, options.normal_radius);
  return computeFpfh(points, normals, tree, options.feature_radius);
}

}  // namespace livo::loop
