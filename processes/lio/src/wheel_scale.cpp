#include "livo/lio/wheel_scale.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <vector>

namespace livo::lio {

namespace {
double sinc(double x) { return std::abs(x) < 1e-6 ? 1.0 - x * x / 6.0 : std::sin(x) / x; }
double seconds(int64_t dt) { return static_cast<double>(dt) * 1e-6; }
}  // namespace

Vec2 predictedWheelTravel(const Pose3& T_W_Ia, const Pose3& T_W_Ib, const Pose3& T_I_B, double track_width,
                          double* forward) {
  const Mat3 R_a = T_W_Ia.linear() * T_I_B.linear();
  const Mat3 R_b = T_W_Ib.linear() * T_I_B.linear();
  const Vec3 p_a = T_W_Ia * T_I_B.translation();
  const Vec3 p_b = T_W_Ib * T_I_B.translation();
  const Vec3 turn = so3::Log(R_a.transpose() * R_b);
  // on an arc of constant curvature the chord points along the mean heading and is the arc
  // length times sinc(yaw / 2)
  const Mat3 R_mid = R_a * so3::Exp(0.5 * turn);
  const double chord = (R_mid.transpose() * (p_b - p_a)).x();
  const double yaw = turn.z();
  const double d = chord / sinc(0.5 * yaw);
  if (forward) *forward = d;
  return Vec2(d - 0.5 * track_width * yaw, d + 0.5 * track_width * yaw);
}

bool integrateWheelSpeeds(const std::deque<WheelSample>& readings, int64_t t0, int64_t t1, double max_gap_s,
                          Vec2* distance, double* noise_gain) {
  if (t1 <= t0 || readings.size() < 2 || readings.front().utime > t0 || readings.back().utime < t1) return false;
  std::vector<double> weight(readings.size(), 0.0);
  Vec2 sum = Vec2::Zero();
  for (size_t i = 1; i < readings.size(); ++i) {
    const WheelSample& a = readings[i - 1];
    const WheelSample& b = readings[i];
    const int64_t u0 = std::max(a.utime, t0), u1 = std::min(b.utime, t1);
    if (u1 <= u0) continue;
    if (seconds(b.utime - a.utime) > max_gap_s) return false;
    // the linear interpolant integrates to its value at the middle times the length
    const double length = seconds(u1 - u0);
    const double alpha = static_cast<double>((u0 + u1) / 2 - a.utime) / static_cast<double>(b.utime - a.utime);
    weight[i - 1] += length * (1.0 - alpha);
    weight[i] += length * alpha;
    sum += length * ((1.0 - alpha) * Vec2(a.left_speed, a.right_speed) + alpha * Vec2(b.left_speed, b.right_speed));
  }
  double gain = 0.0;
  for (double w : weight) gain += w * w;
  *distance = sum;
  *noise_gain = gain;
  return true;
}

WheelScaleEstimator::WheelScaleEstimator(const WheelScaleOptions& options, double speed_noise_std)
    : options_(options), speed_variance_(speed_noise_std * speed_noise_std) {
  covariance_ = Mat2::Identity() * options.prior_std * options.prior_std;
}

WheelScaleEstimator::Outcome WheelScaleEstimator::update(const WheelTravel& t, int64_t utime) {
  if (has_time_ && utime > last_utime_)
    covariance_ += Mat2::Identity() * options_.random_walk * options_.random_walk * seconds(utime - last_utime_);
  last_utime_ = utime;
  has_time_ = true;
  if (!(t.duration_s > 0.0 && t.duration_s <= options_.max_interval_s) ||
      !(std::abs(t.forward_distance) >= options_.min_speed * t.duration_s)) {
    ++counts_.unobservable;
    return Outcome::kUnobservable;
  }
  // measured_i = s_i true_i + n_i and predicted_i = true_i + e (the displacement error, common to
  // both sides): the innovation's covariance is H P H^T + s s^T sigma_d^2 + sigma_n^2 I
  const Mat2 H = t.predicted.asDiagonal();
  const Vec2 y = t.measured - scale_.cwiseProduct(t.predicted);
  const double sd = options_.displacement_noise_std;
  const Mat2 R = scale_ * scale_.transpose() * sd * sd + Mat2::Identity() * speed_variance_ * t.measured_noise_gain;
  const Mat2 S = H * covariance_ * H.transpose() + R;
  const Eigen::LLT<Mat2> llt(S);
  if (llt.info() != Eigen::Success) {
    ++counts_.unobservable;
    return Outcome::kUnobservable;
  }
  last_chi2_ = y.dot(llt.solve(y));
  if (!(last_chi2_ <= options_.gate_chi2)) {
    ++counts_.outliers;
    return Outcome::kOutlier;
  }
  const Mat2 K = llt.solve(H * covariance_).transpose();
  scale_ += K * y;
  const Mat2 IKH = Mat2::Identity() - K * H;
  const Mat2 P = IKH * covariance_ * IKH.transpose() + K * R * K.transpose();
  covariance_ = 0.5 * (P + P.transpose());
  ++counts_.learned;
  return Outcome::kLearned;
}

WheelSample WheelScaleEstimator::correct(const WheelSample& raw) const {
  WheelSample w = raw;
  w.left_speed = raw.left_speed / scale_.x();
  w.right_speed = raw.right_speed / scale_.y();
  return w;
}

double WheelScaleEstimator::meanSpeedVariance(const WheelSample& raw) const {
  const Vec2 J(-0.5 * raw.left_speed / (scale_.x() * scale_.x()), -0.5 * raw.right_speed / (scale_.y() * scale_.y()));
  return J.dot(covariance_ * J);
}

}  // namespace livo::lio
