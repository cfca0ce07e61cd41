#include "livo/lio/undistorter.hpp"

#include <algorithm>
#include <stdexcept>

namespace livo::lio {

Mat3 expSmall(const Vec3& w) {
  const double t2 = w.squaredNorm();
  if (t2 > 2.5e-3) return so3::Exp(w);
  // sin(t)/t and (1-cos t)/t^2 by their series; the first dropped terms are below 1e-16.
  const double a = 1.0 - t2 / 6.0 * (1.0 - t2 / 20.0 * (1.0 - t2 / 42.0));
  const double b = 0.5 * (1.0 - t2 / 12.0 * (1.0 - t2 / 30.0 * (1.0 - t2 / 56.0)));
  const Mat3 W = so3::hat(w);
  return Mat3::Identity() + a * W + b * W * W;
}

Undistorter::Undistorter(const std::vector<ImuSegment>& segments, const Mat3& R_end, const Vec3& p_end,
                         int64_t end_utime, const Pose3& T_I_L)
    : end_utime_(end_utime), R_IL_(T_I_L.linear()), t_IL_(T_I_L.translation()) {
  if (segments.empty()) throw std::invalid_argument("Undistorter needs at least one IMU segment");
  const Mat3 RT = R_end.transpose();
  segs_.reserve(segments.size());
  for (const auto& s : segments) {
    Seg g;
    g.t0 = static_cast<double>(s.utime - end_utime) * 1e-6;
    g.R = RT * s.rot;
    g.p = RT * (s.pos - p_end);
    g.v = RT * s.vel;
    g.a = RT * s.acc_world;
    g.omega = s.omega;
    segs_.push_back(g);
  }
}

Vec3 Undistorter::toEndRelative(const Vec3& p_L, double t) const {
  // last segment starting at or before t (the first one for earlier points: extrapolated)
  auto it = std::upper_bound(segs_.begin(), segs_.end(), t, [](double tt, const Seg& s) { return tt < s.t0; });
  const Seg& s = it == segs_.begin() ? segs_.front() : *(it - 1);
  const double dt = t - s.t0;
  const Vec3 p_I = R_IL_ * p_L + t_IL_;
  return s.R * (expSmall(s.omega * dt) * p_I) + s.p + s.v * dt + 0.5 * dt * dt * s.a;
}

void Undistorter::undistort(const LidarScan& scan, int64_t first_utime_imu, const std::vector<size_t>& indices,
                            std::vector<Vec3>* out) const {
  out->resize(indices.size());
  const double base = static_cast<double>(first_utime_imu - end_utime_) * 1e-6;
  for (size_t i = 0; i < indices.size(); ++i) {
    const size_t j = indices[i];
    (*out)[i] = toEndRelative(scan.points[j], base + static_cast<double>(scan.time_offset[j]));
  }
}

}  // namespace livo::lio
