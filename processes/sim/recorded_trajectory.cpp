#include "recorded_trajectory.hpp"

#include <algorithm>
#include <stdexcept>

namespace livo {
namespace sim {

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

std::vector<double> RecordedTrajectory::times(const livo::Trajectory& poses) {
  if (poses.size() < 4) throw std::invalid_argument("a recorded trajectory needs at least 4 poses");
  std::vector<double> t;
  for (const auto& p : poses) t.push_back(p.stamp - poses.front().stamp);
  return t;
}

std::vector<NaturalCubicSpline::Value> RecordedTrajectory::values(const livo::Trajectory& poses) {
  std::vector<NaturalCubicSpline::Value> v;
  Quat prev = Quat::Identity();
  for (size_t i = 0; i < poses.size(); ++i) {
    Quat q(poses[i].pose.linear());
    q.normalize();
    if (i > 0 && q.coeffs().dot(prev.coeffs()) < 0.0) q.coeffs() = -q.coeffs();  // continuous sign
    prev = q;
    NaturalCubicSpline::Value x;
    x << poses[i].pose.translation(), q.w(), q.x(), q.y(), q.z();
    v.push_back(x);
  }
  return v;
}

RecordedTrajectory::RecordedTrajectory(const livo::Trajectory& poses)
    : start_stamp_(poses.empty() ? 0.0 : poses.front().stamp), spline_(times(poses), values(poses)) {
  duration_ = poses.back().stamp - poses.front().stamp;
}

BodyState RecordedTrajectory::at(double t) const {
  NaturalCubicSpline::Value y, dy, ddy;
  spline_.eval(t, &y, &dy, &ddy);
  BodyState s;
  const Eigen::Vector4d u = y.tail<4>(), du = dy.tail<4>();
  const double n = u.norm();
  const Eigen::Vector4d qv = u / n;
  const Eigen::Vector4d dq = (du - qv * qv.dot(du)) / n;
  const Quat q(qv[0], qv[1], qv[2], qv[3]), qd(dq[0], dq[1], dq[2], dq[3]);
  s.T_W_I.linear() = q.toRotationMatrix();
  s.T_W_I.translation() = y.head<3>();
  s.velocity = dy.head<3>();
  s.acceleration = ddy.head<3>();
  s.angular_velocity = 2.0 * (q.conjugate() * qd).vec();
  return s;
}

}  // namespace sim
}  // namespace livo
