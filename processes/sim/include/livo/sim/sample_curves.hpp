// C2 curves through or near samples (t_i, y_i), y in R^7 (a recorded pose: position and the
// sign-aligned quaternion w, x, y, z), evaluated with their first two derivatives:
//   NaturalCubicSpline     interpolates the samples (natural ends);
//   SmoothingCubicBSpline  a least-squares uniform cubic B-spline with knots every `spacing`
//                          seconds, for noisy samples (motion capture jitter would otherwise be
//                          differentiated twice).
#pragma once

#include <vector>

#include <Eigen/Core>

namespace livo::sim {

class SampledCurve {
 public:
  using Value = Eigen::Matrix<double, 7, 1>;
  virtual ~SampledCurve() = default;
  /// Value and first two derivatives at t; t is clamped to the samples' span.
  virtual void eval(double t, Value* y, Value* dy, Value* ddy) const = 0;
};

/// Natural cubic spline through (t_i, y_i); times strictly increasing, at least 3 samples.
class NaturalCubicSpline : public SampledCurve {
 public:
  NaturalCubicSpline(std::vector<double> times, std::vector<Value> values);
  void eval(double t, Value* y, Value* dy, Value* ddy) const override;

 private:
  std::vector<double> t_;
  std::vector<Value> y_, m_;  // values and second derivatives at the knots
};

/// Least-squares fit of a uniform cubic B-spline to (t_i, y_i): knots from t_0 to t_n-1, evenly
/// spaced at most `spacing` apart (the span divided into ceil(span / spacing) intervals). The
/// sum of squared residuals is minimised plus kGapPenalty times the squared second differences
/// of neighbouring control points: negligible where there are samples (a sample's weight is 1 and
/// an interval holds many), it decides the curve where an interval has none, which it bridges in a
/// straight line (so recordings with dropouts still give a well-posed fit). Times non-decreasing
/// (repeated stamps are fine), at least 2 distinct.
class SmoothingCubicBSpline : public SampledCurve {
 public:
  static constexpr double kGapPenalty = 1e-3;
  SmoothingCubicBSpline(const std::vector<double>& times, const std::vector<Value>& values, double spacing);
  void eval(double t, Value* y, Value* dy, Value* ddy) const override;
  double knotSpacing() const { return h_; }
  int intervals() const { return intervals_; }

 private:
  double t0_ = 0.0, h_ = 1.0;
  int intervals_ = 1;
  std::vector<Value> control_;  // intervals_ + 3 control points
};

}  // namespace livo::sim
