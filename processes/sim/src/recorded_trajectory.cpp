#include "livo/sim/recorded_trajectory.hpp"

#include <stdexcept>

namespace livo::sim {

livo::Trajectory placeRecording(const livo::Trajectory& poses, const Pose3& placement, const Pose3& body_in_recorded) {
  livo::Trajectory placed = poses;
  for (StampedPose& p : placed) p.pose = placement * p.pose * body_in_recorded;
  return placed;
}

std::vector<double> RecordedTrajectory::times(const livo::Trajectory& poses) {
  if (poses.size() < 4) throw std::invalid_argument("a recorded trajectory needs at least 4 poses");
  std::vector<double> t;
  for (const auto& p : poses) t.push_back(p.stamp - poses.front().stamp);
  return t;
}

std::vector<SampledCurve::Value> RecordedTrajectory::values(const livo::Trajectory& poses) {
  std::vector<SampledCurve::Value> v;
  Quat prev = Quat::Identity();
  for (size_t i = 0; i < poses.size(); ++i) {
    Quat q(poses[i].pose.linear());
    q.normalize();
    if (i > 0 && q.coeffs().dot(prev.coeffs()) < 0.0) q.coeffs() = -q.coeffs();  // continuous sign
    prev = q;
    SampledCurve::Value x;
    x << poses[i].pose.translation(), q.w(), q.x(), q.y(), q.z();
    v.push_back(x);
  }
  return v;
}

RecordedTrajectory::RecordedTrajectory(const livo::Trajectory& recorded, const RecordedMotionOptions& options) {
  const livo::Trajectory poses = placeRecording(recorded, options.placement, options.body_in_recorded);
  if (options.smoothing_s > 0.0)
    curve_ = std::make_unique<SmoothingCubicBSpline>(times(poses), values(poses), options.smoothing_s);
  else
    curve_ = std::make_unique<NaturalCubicSpline>(times(poses), values(poses));
  start_stamp_ = poses.front().stamp;
  duration_ = poses.back().stamp - poses.front().stamp;
}

BodyState RecordedTrajectory::at(double t) const {
  SampledCurve::Value y, dy, ddy;
  curve_->eval(t, &y, &dy, &ddy);
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

}  // namespace livo::sim
