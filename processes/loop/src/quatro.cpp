#include "livo/loop/quatro.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/SVD>

namespace livo::loop {

namespace {
Mat3 weightedRotation(const Points& a, const Points& b, const std::vector<double>& w, bool yaw_only) {
  if (yaw_only) {
    // argmax over yaw of sum w (Rz a)·b, in the xy plane: closed form.
    double s = 0.0, c = 0.0;
    for (size_t i = 0; i < a.size(); ++i) {
      s += w[i] * (a[i].x() * b[i].y() - a[i].y() * b[i].x());
      c += w[i] * (a[i].x() * b[i].x() + a[i].y() * b[i].y());
    }
    return Eigen::AngleAxisd(std::atan2(s, c), Vec3::UnitZ()).toRotationMatrix();
  }
  Mat3 H = Mat3::Zero();
  for (size_t i = 0; i < a.size(); ++i) H += w[i] * b[i] * a[i].transpose();
  Eigen::JacobiSVD<Mat3> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 D = Mat3::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}
}  // namespace

Mat3 gncTlsRotation(const Points& a, const Points& b, double noise_bound, bool yaw_only, const QuatroOptions& options,
                    std::vector<double>* weights_out) {
  const size_t n = a.size();
  std::vector<double> w(n, 1.0), r2(n);
  Mat3 R = weightedRotation(a, b, w, yaw_only);
  const double c2 = noise_bound * noise_bound;
  auto residuals = [&](const Mat3& Rm) {
    double mx = 0.0;
    for (size_t i = 0; i < n; ++i) mx = std::max(mx, r2[i] = (Rm * a[i] - b[i]).squaredNorm());
    return mx;
  };
  const double max_r2 = residuals(R);
  double mu = 1.0 / (2.0 * max_r2 / c2 - 1.0);
  if (max_r2 > c2 && mu > 0.0) {
    double prev_cost = std::numeric_limits<double>::infinity();
    for (int it = 0; it < options.gnc_max_iterations; ++it) {
      const double th_in = mu / (mu + 1.0) * c2, th_out = (mu + 1.0) / mu * c2;
      for (size_t i = 0; i < n; ++i) {
        if (r2[i] <= th_in)
          w[i] = 1.0;
        else if (r2[i] >= th_out)
          w[i] = 0.0;
        else
          w[i] = std::sqrt(c2 * mu * (mu + 1.0) / r2[i]) - mu;
      }
      R = weightedRotation(a, b, w, yaw_only);
      residuals(R);
      double cost = 0.0;
      bool binary = true;
      for (size_t i = 0; i < n; ++i) {
        cost += w[i] * r2[i];
        if (w[i] > 1e-9 && w[i] < 1.0 - 1e-9) binary = false;
      }
      if (binary && std::abs(cost - prev_cost) < options.gnc_cost_threshold) break;
      prev_cost = cost;
      mu *= options.gnc_factor;
    }
  }
  if (weights_out) *weights_out = w;
  return R;
}

double adaptiveVoting(const std::vector<double>& values, double bound) {
  const size_t n = values.size();
  if (n == 0) return 0.0;
  // Endpoints of the intervals [v - bound, v + bound]; between consecutive endpoints the
  // consensus set is constant: pick the one with the lowest TLS cost.
  std::vector<std::pair<double, size_t>> ev;
  ev.reserve(2 * n);
  for (size_t i = 0; i < n; ++i) {
    ev.push_back({values[i] - bound, 2 * i});      // enter
    ev.push_back({values[i] + bound, 2 * i + 1});  // leave
  }
  std::sort(ev.begin(), ev.end(), [](const auto& x, const auto& y) {
    return x.first < y.first || (x.first == y.first && (x.second & 1) < (y.second & 1));
  });
  double sum = 0.0, sum2 = 0.0, best_cost = std::numeric_limits<double>::infinity(), best = values[0];
  int count = 0;
  const double b2 = bound * bound;
  for (const auto& [pos, code] : ev) {
    const double v = values[code / 2];
    if (code & 1) {
      sum -= v;
      sum2 -= v * v;
      --count;
    } else {
      sum += v;
      sum2 += v * v;
      ++count;
      const double mean = sum / count;
      const double cost = (sum2 - count * mean * mean) + static_cast<double>(n - count) * b2;
      if (cost < best_cost) {
        best_cost = cost;
        best = mean;
      }
    }
  }
  return best;
}

QuatroResult quatroRegister(const Points& source, const Points& target, const Correspondences& matches,
                            const QuatroOptions& options) {
  QuatroResult res;
  res.num_correspondences = static_cast<int>(matches.size());
  if (matches.size() < 3) return res;
  const Graph g = consistencyGraph(source, target, matches, options.noise_bound);
  const std::vector<int> clique = maximumClique(g, options.clique, &res.clique_exact);
  res.num_clique = static_cast<int>(clique.size());
  if (clique.size() < 3) return res;

  // Translation-invariant measurements: all pairs of clique members, subsampled evenly if many.
  const size_t m = clique.size();
  const size_t pairs = m * (m - 1) / 2;
  const size_t stride = std::max<size_t>(1, (pairs + options.max_tims - 1) / std::max(options.max_tims, 1));
  Points a, b;
  a.reserve(pairs / stride + 1);
  b.reserve(pairs / stride + 1);
  size_t k = 0;
  for (size_t i = 0; i < m; ++i)
    for (size_t j = i + 1; j < m; ++j, ++k) {
      if (k % stride) continue;
      const Correspondence& ci = matches[clique[i]];
      const Correspondence& cj = matches[clique[j]];
      a.push_back(source[cj.source] - source[ci.source]);
      b.push_back(target[cj.target] - target[ci.target]);
    }
  const Mat3 R = gncTlsRotation(a, b, 2.0 * options.noise_bound, options.quasi_so3, options);

  // COTE: each translation component by adaptive voting over the clique.
  Vec3 t;
  std::vector<double> values(m);
  for (int axis = 0; axis < 3; ++axis) {
    for (size_t i = 0; i < m; ++i) {
      const Correspondence& c = matches[clique[i]];
      values[i] = (target[c.target] - R * source[c.source])[axis];
    }
    t[axis] = adaptiveVoting(values, options.noise_bound);
  }
  res.T_target_source.linear() = R;
  res.T_target_source.translation() = t;
  for (int ci : clique) {
    const Correspondence& c = matches[ci];
    if ((res.T_target_source * source[c.source] - target[c.target]).norm() <= 2.0 * options.noise_bound)
      ++res.num_inliers;
  }
  res.valid = res.num_inliers >= 3;
  return res;
}

}  // namespace livo::loop
