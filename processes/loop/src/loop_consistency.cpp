#include "livo/loop/loop_consistency.hpp"

#include <cmath>

#include <Eigen/Cholesky>

namespace livo::loop {

Mat6 driftCovariance(double path_m, const DriftModel& m) {
  const double L = std::abs(path_m);
  const double sr = std::hypot(m.rotation_floor, m.rotation_per_m * L);
  const double st =
      std::hypot(std::hypot(m.translation_floor, m.translation_per_m * L), 0.5 * m.rotation_per_m * L * L);
  Vec6 var;
  var << Vec3::Constant(sr * sr), Vec3::Constant(st * st);
  return var.asDiagonal();
}

double poseChi2(const Pose3& predicted, const Mat6& cov_predicted, const Pose3& measured, const Mat6& cov_measured) {
  Vec6 e;
  e.head<3>() = so3::Log(Mat3(predicted.linear().transpose() * measured.linear()));
  e.tail<3>() = predicted.linear().transpose() * (measured.translation() - predicted.translation());
  const Mat6 S = 0.5 * (cov_predicted + cov_measured + (cov_predicted + cov_measured).transpose());
  return e.dot(S.ldlt().solve(e));
}

}  // namespace livo::loop
