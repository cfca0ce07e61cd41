#include "livo/sim/sample_curves.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Sparse>

namespace livo::sim {

NaturalCubicSpline::NaturalCubicSpline(std::vector<double> times, std::vector<Value> values)
    : t_(std::move(times)), y_(std::move(values)) {
  const size_t n = t_.size();
  if (n < 3 || y_.size() != n) throw std::invalid_argument("cubic spline needs at least 3 samples");
  for (size_t i = 1; i < n; ++i)
    if (!(t_[i] > t_[i - 1])) throw std::invalid_argument("cubic spline samples must have increasing times");
  // tridiagonal system for the second derivatives, natural ends (Thomas algorithm)
  m_.assign(n, Value::Zero());
  std::vector<double> c(n, 0.0);
  std::vector<Value> d(n, Value::Zero());
  for (size_t i = 1; i + 1 < n; ++i) {
    const double h0 = t_[i] - t_[i - 1], h1 = t_[i + 1] - t_[i];
    const double a = h0 / 6.0, b = (h0 + h1) / 3.0, cc = h1 / 6.0;
    const Value r = (y_[i + 1] - y_[i]) / h1 - (y_[i] - y_[i - 1]) / h0;
    const double denom = b - a * c[i - 1];
    c[i] = cc / denom;
    d[i] = (r - a * d[i - 1]) / denom;
  }
  for (size_t i = n - 2; i >= 1; --i) {
    m_[i] = d[i] - c[i] * m_[i + 1];
    if (i == 1) break;
  }
}

void NaturalCubicSpline::eval(double t, Value* y, Value* dy, Value* ddy) const {
  t = std::clamp(t, t_.front(), t_.back());
  size_t i = static_cast<size_t>(std::upper_bound(t_.begin(), t_.end(), t) - t_.begin());
  i = std::clamp<size_t>(i, 1, t_.size() - 1) - 1;
  const double h = t_[i + 1] - t_[i];
  const double a = (t_[i + 1] - t) / h, b = (t - t_[i]) / h;
  *y = a * y_[i] + b * y_[i + 1] + ((a * a * a - a) * m_[i] + (b * b * b - b) * m_[i + 1]) * (h * h / 6.0);
  *dy = (y_[i + 1] - y_[i]) / h + ((1.0 - 3.0 * a * a) * m_[i] + (3.0 * b * b - 1.0) * m_[i + 1]) * (h / 6.0);
  *ddy = a * m_[i] + b * m_[i + 1];
}

namespace {

/// The four uniform cubic B-spline basis functions on an interval (u in [0, 1]) and their first
/// and second derivatives in u; they weigh control points i .. i + 3 of interval i.
struct CubicBasis {
  double b[4], d1[4], d2[4];
  explicit CubicBasis(double u) {
    const double v = 1.0 - u, u2 = u * u, u3 = u2 * u;
    b[0] = v * v * v / 6.0;
    b[1] = (3.0 * u3 - 6.0 * u2 + 4.0) / 6.0;
    b[2] = (-3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0) / 6.0;
    b[3] = u3 / 6.0;
    d1[0] = -0.5 * v * v;
    d1[1] = 1.5 * u2 - 2.0 * u;
    d1[2] = -1.5 * u2 + u + 0.5;
    d1[3] = 0.5 * u2;
    d2[0] = v;
    d2[1] = 3.0 * u - 2.0;
    d2[2] = 1.0 - 3.0 * u;
    d2[3] = u;
  }
};

}  // namespace

SmoothingCubicBSpline::SmoothingCubicBSpline(const std::vector<double>& times, const std::vector<Value>& values,
                                             double spacing) {
  const size_t n = times.size();
  if (values.size() != n || n < 2) throw std::invalid_argument("smoothing spline needs at least 2 samples");
  if (!(spacing > 0.0)) throw std::invalid_argument("smoothing spline knot spacing must be > 0");
  for (size_t i = 1; i < n; ++i)
    if (!(times[i] >= times[i - 1])) throw std::invalid_argument("smoothing spline samples must not go back in time");
  const double span = times.back() - times.front();
  if (!(span > 0.0)) throw std::invalid_argument("smoothing spline samples must span some time");
  t0_ = times.front();
  intervals_ = std::max(1, static_cast<int>(std::ceil(span / spacing - 1e-9)));
  h_ = span / intervals_;

  // normal equations (B^T B + kGapPenalty D^T D) c = B^T y, banded (half-bandwidth 3)
  const int m = intervals_ + 3;
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(16 * n + 9 * static_cast<size_t>(m));
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(m, 7);
  for (size_t s = 0; s < n; ++s) {
    const double x = (times[s] - t0_) / h_;
    const int i = std::clamp(static_cast<int>(std::floor(x)), 0, intervals_ - 1);
    const CubicBasis basis(x - i);
    for (int a = 0; a < 4; ++a) {
      rhs.row(i + a) += basis.b[a] * values[s].transpose();
      for (int b = 0; b < 4; ++b) entries.emplace_back(i + a, i + b, basis.b[a] * basis.b[b]);
    }
  }
  const double second_difference[3] = {1.0, -2.0, 1.0};
  for (int j = 0; j + 2 < m; ++j)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        entries.emplace_back(j + a, j + b, kGapPenalty * second_difference[a] * second_difference[b]);
  Eigen::SparseMatrix<double> normal(m, m);
  normal.setFromTriplets(entries.begin(), entries.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
  if (solver.info() != Eigen::Success) throw std::runtime_error("smoothing spline: the normal equations are singular");
  const Eigen::MatrixXd control = solver.solve(rhs);
  control_.resize(static_cast<size_t>(m));
  for (int j = 0; j < m; ++j) control_[static_cast<size_t>(j)] = control.row(j).transpose();
}

void SmoothingCubicBSpline::eval(double t, Value* y, Value* dy, Value* ddy) const {
  const double x = std::clamp((t - t0_) / h_, 0.0, static_cast<double>(intervals_));
  const int i = std::min(static_cast<int>(std::floor(x)), intervals_ - 1);
  const CubicBasis basis(x - i);
  y->setZero(), dy->setZero(), ddy->setZero();
  for (int a = 0; a < 4; ++a) {
    const Value& c = control_[static_cast<size_t>(i + a)];
    *y += basis.b[a] * c;
    *dy += basis.d1[a] * c;
    *ddy += basis.d2[a] * c;
  }
  *dy /= h_;
  *ddy /= h_ * h_;
}

}  // namespace livo::sim
