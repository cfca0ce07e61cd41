#include "livo/lio/undistorter.hpp"

#include <algorithm>
#include <stdexcept>

namespace livo::lio {

namespace {
// expSmallTimes, inlined into the per-point loop (a call per point cost a fifth of the undistortion;
// GCC does not inline it unasked)
[[gnu::always_inline]] inline Vec3 expSmallTimesInline(const Vec3& w, const Vec3& v) {
  const double t2 = w.squaredNorm();
  if (t2 > 2.5e-3) return so3::Exp(w) * v;
  // sin(t)/t and (1-cos t)/t^2 by their series; the first dropped terms are below 1e-16.
  // (products with constant reciprocals: a division each would cost more than the rest of a point)
  const double a = 1.0 - t2 * (1.0 / 6.0) * (1.0 - t2 * (1.0 / 20.0) * (1.0 - t2 * (1.0 / 42.0)));
  const double b = 0.5 * (1.0 - t2 * (1.0 / 12.0) * (1.0 - t2 * (1.0 / 30.0) * (1.0 - t2 * (1.0 / 56.0))));
  // (I + a W + b W^2) v with W v = w x v: two cross products instead of building W and W^2
  const Vec3 wv = w.cross(v);
  return v + a * wv + b * w.cross(wv);
}
}  // namespace

Vec3 expSmallTimes(const Vec3& w, const Vec3& v) { return expSmallTimesInline(w, v); }

Undistorter::Undistorter(const std::vector<ImuSegment>& segments, const Mat3& R_end, const Vec3& p_end,
                         int64_t end_utime, const Pose3& T_I_L)
    : end_utime_(end_utime) {
  if (segments.empty()) throw std::invalid_argument("Undistorter needs at least one IMU segment");
  const Mat3 RT = R_end.transpose();
  segs_.reserve(segments.size());
  for (const auto& s : segments) {
    Seg g;
    g.t0 = static_cast<double>(s.utime - end_utime) * 1e-6;
    const Mat3 R = RT * s.rot;
    g.R_L = R * T_I_L.linear();
    g.t_L = R * T_I_L.translation();
    g.p = RT * (s.pos - p_end);
    g.v = RT * s.vel;
    g.a = RT * s.acc_world;
    g.omega = R * s.omega;
    segs_.push_back(g);
  }
}

size_t Undistorter::segmentAt(double t) const {
  // last segment starting at or before t (the first one for earlier points: extrapolated)
  auto it = std::upper_bound(segs_.begin(), segs_.end(), t, [](double tt, const Seg& s) { return tt < s.t0; });
  return it == segs_.begin() ? 0 : static_cast<size_t>(it - segs_.begin()) - 1;
}

[[gnu::always_inline]] inline Vec3 Undistorter::moveToEnd(const Vec3& p_L, double t, size_t seg) const {
  // R_k Exp(w dt) (R_IL p_L + t_IL) = Exp(R_k w dt) (R_k R_IL p_L + R_k t_IL): one rotation of the
  // point, with the segment's products made once
  const Seg& s = segs_[seg];
  const double dt = t - s.t0;
  return expSmallTimesInline(s.omega * dt, s.R_L * p_L + s.t_L) + s.p + s.v * dt + 0.5 * dt * dt * s.a;
}

Vec3 Undistorter::toEndRelative(const Vec3& p_L, double t) const { return moveToEnd(p_L, t, segmentAt(t)); }

void Undistorter::undistort(const LidarScan& scan, int64_t first_utime_imu, double time_shift,
                            const std::vector<size_t>& indices, std::vector<Vec3>* out) const {
  out->resize(indices.size());
  const double base = static_cast<double>(first_utime_imu - end_utime_) * 1e-6 + time_shift;
  // A sweep's points come (mostly) in time order: the previous point's segment is checked before
  // a binary search (the same segment as segmentAt's).
  size_t seg = 0;
  for (size_t i = 0; i < indices.size(); ++i) {
    const size_t j = indices[i];
    const double t = base + static_cast<double>(scan.time_offset[j]);
    const bool in_seg = (seg == 0 || segs_[seg].t0 <= t) && (seg + 1 == segs_.size() || t < segs_[seg + 1].t0);
    if (!in_seg) seg = segmentAt(t);
    (*out)[i] = moveToEnd(scan.points[j], t, seg);
  }
}

}  // namespace livo::lio
