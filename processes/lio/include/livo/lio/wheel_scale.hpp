// Online calibration of the wheel encoders' scale factors, beside the ESIKF (whose state is fixed):
// a measured speed is s * the true speed of its contact point (tyre radius, pressure, load), one
// scale s per side. Between two registered sweeps the LiDAR poses give the distance each contact
// point travelled (forward displacement of the wheel base B -/+ half the track times its yaw
// change); the encoders' speeds integrated over the same interval measure s times it. A 2-state
// Kalman filter (prior 1 with prior_std, a random walk for slow changes) fuses those, with a
// chi-square gate against slip. Standing still and turning on the spot (B's forward speed below
// min_speed) teach nothing and leave the estimate alone. The estimated scales divide the encoder
// speeds before the wheel velocity update, and their uncertainty widens its forward variance.
#pragma once

#include <cstdint>
#include <deque>

#include "livo/lio/wheel_update.hpp"

namespace livo::lio {

using Mat2 = Eigen::Matrix2d;

struct WheelScaleOptions {
  bool enabled = true;
  double prior_std = 0.05;                // of each scale around 1 (tyre radius: a few per cent)
  double random_walk = 1e-4;              // 1/sqrt(s): slow changes (tyre pressure, load)
  double displacement_noise_std = 0.005;  // m, the LiDAR's forward displacement of B over one sweep
  double min_speed = 0.5;                 // m/s, B's forward speed below which nothing is learned
  double gate_chi2 = 13.82;               // 2 dof, 0.1 %: larger innovations (slip) are not learned
  double max_interval_s = 0.5;            // registered sweeps further apart are not compared
};

/// What the two contact points travelled between two registered sweeps.
struct WheelTravel {
  double duration_s = 0.0;
  double forward_distance = 0.0;     // m, of B along its own x axis (from the poses)
  Vec2 predicted = Vec2::Zero();     // m, left and right, from the poses
  Vec2 measured = Vec2::Zero();      // m, left and right, integrated encoder speeds
  double measured_noise_gain = 0.0;  // variance of a measured distance / speed_noise_std^2
};

/// Left and right distance travelled by B's contact points (B: x forward, z up, wheels at
/// y = +/- track/2) from two poses W_T_I, along the arc of constant curvature that joins them.
/// *forward (optional): B's forward distance.
Vec2 predictedWheelTravel(const Pose3& T_W_Ia, const Pose3& T_W_Ib, const Pose3& T_I_B, double track_width,
                          double* forward = nullptr);

/// Integral of the left and right speeds over [t0, t1] (readings linearly interpolated, as the
/// wheel update does), and the sum of the squared weights of the readings (the variance of the
/// integral over the variance of one reading). False unless readings cover [t0, t1] without a gap
/// longer than max_gap_s.
bool integrateWheelSpeeds(const std::deque<WheelSample>& readings, int64_t t0, int64_t t1, double max_gap_s,
                          Vec2* distance, double* noise_gain);

class WheelScaleEstimator {
 public:
  enum class Outcome { kLearned, kUnobservable, kOutlier };
  struct Counts {
    int64_t learned = 0;
    int64_t unobservable = 0;  // too slow, or too long an interval
    int64_t outliers = 0;      // gated (slip)
  };

  /// speed_noise_std: of one encoder reading (the rig's wheel.speed_noise_std).
  WheelScaleEstimator(const WheelScaleOptions& options, double speed_noise_std);

  /// Learns from one interval ending at `utime` (the random walk runs from the previous update).
  Outcome update(const WheelTravel& travel, int64_t utime);
  /// The encoder speeds divided by the scales.
  WheelSample correct(const WheelSample& raw) const;
  /// Variance of the corrected mean speed 0.5 (l / s_l + r / s_r) due to the scales' uncertainty.
  double meanSpeedVariance(const WheelSample& raw) const;

  const Vec2& scales() const { return scale_; }  // left, right
  Vec2 stds() const { return covariance_.diagonal().cwiseSqrt(); }
  const Mat2& covariance() const { return covariance_; }
  const Counts& counts() const { return counts_; }
  /// Chi-square of the last interval that was observable (learned or gated).
  double lastChi2() const { return last_chi2_; }

 private:
  WheelScaleOptions options_;
  double speed_variance_;
  Vec2 scale_ = Vec2::Ones();
  Mat2 covariance_;
  int64_t last_utime_ = 0;
  bool has_time_ = false;
  Counts counts_;
  double last_chi2_ = 0.0;
};

}  // namespace livo::lio
