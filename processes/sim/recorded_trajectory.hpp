// Motion of a real recording: ground-truth poses (e.g. 20 Hz Vicon) interpolated by natural
// cubic splines (C2) in position and in the sign-aligned quaternion (normalised), so a LiDAR or
// camera can be placed at any instant along the real motion.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "livo/trajectory_io.hpp"
#include "trajectory.hpp"

namespace livo {
namespace sim {

/// Natural cubic spline through (t_i, y_i), y in R^7, evaluated with two derivatives.
class NaturalCubicSpline {
 public:
  using Value = Eigen::Matrix<double, 7, 1>;
  NaturalCubicSpline(std::vector<double> times, std::vector<Value> values);
  void eval(double t, Value* y, Value* dy, Value* ddy) const;

 private:
  std::vector<double> t_;
  std::vector<Value> y_, m_;  // values and second derivatives at the knots
};

class RecordedTrajectory : public BodyTrajectory {
 public:
  /// `poses` must hold at least 4 poses with increasing stamps; time 0 is the first stamp.
  explicit RecordedTrajectory(const livo::Trajectory& poses);
  BodyState at(double t) const override;
  double duration() const override { return duration_; }
  double startStamp() const { return start_stamp_; }

 private:
  static std::vector<double> times(const livo::Trajectory& poses);
  static std::vector<NaturalCubicSpline::Value> values(const livo::Trajectory& poses);
  double start_stamp_ = 0.0, duration_ = 0.0;
  NaturalCubicSpline spline_;
};

}  // namespace sim
}  // namespace livo
