#include "livo/evaluate/attitude_error.hpp"

#include <cmath>

namespace livo::evaluate {

namespace {
constexpr double kDegPerRad = 180.0 / M_PI;

/// a - b wrapped to (-pi, pi].
double angleDifference(double a, double b) {
  double d = std::remainder(a - b, 2.0 * M_PI);
  if (d <= -M_PI) d += 2.0 * M_PI;
  return d;
}

/// The angle between two unit vectors, accurate near 0 (atan2 of |a x b| and a . b).
double angleBetween(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }
}  // namespace

RollPitch rollPitchOf(const Mat3& R) {
  RollPitch rp;
  rp.roll = std::atan2(R(2, 1), R(2, 2));
  rp.pitch = std::atan2(-R(2, 0), std::hypot(R(2, 1), R(2, 2)));
  return rp;
}

AttitudeError attitudeError(const std::vector<Pose3>& gt, const std::vector<Pose3>& est) {
  AttitudeError e;
  for (size_t k = 0; k < gt.size() && k < est.size(); ++k) {
    const Mat3 R_gt = gt[k].linear(), R_est = est[k].linear();
    const RollPitch g = rollPitchOf(R_gt), s = rollPitchOf(R_est);
    e.roll_deg.push_back(angleDifference(s.roll, g.roll) * kDegPerRad);
    e.pitch_deg.push_back((s.pitch - g.pitch) * kDegPerRad);
    const Vec3 up_in_gt_body = R_gt.row(2).transpose(), up_in_est_body = R_est.row(2).transpose();
    e.tilt_deg.push_back(angleBetween(up_in_est_body.normalized(), up_in_gt_body.normalized()) * kDegPerRad);
  }
  e.roll = summarizeErrors(e.roll_deg);
  e.pitch = summarizeErrors(e.pitch_deg);
  e.tilt = summarizeErrors(e.tilt_deg);
  return e;
}

}  // namespace livo::evaluate
