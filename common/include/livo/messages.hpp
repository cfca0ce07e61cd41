// Conversions between the LCM types and Eigen, in one place.
#pragma once

#include <cmath>

#include "livo/filter_state.hpp"
#include "livo/so3.hpp"

namespace livo {

/// Quaternion from [w, x, y, z] (as stored in every message), normalised.
inline Quat quatFromWxyz(const double q[4]) { return Quat(q[0], q[1], q[2], q[3]).normalized(); }
inline void quatToWxyz(const Quat& q_in, double out[4]) {
  const Quat q = q_in.normalized();
  out[0] = q.w();
  out[1] = q.x();
  out[2] = q.y();
  out[3] = q.z();
}

inline Pose3 poseFrom(const double position[3], const double orientation_wxyz[4]) {
  Pose3 T = Pose3::Identity();
  T.linear() = quatFromWxyz(orientation_wxyz).toRotationMatrix();
  T.translation() = Vec3(position[0], position[1], position[2]);
  return T;
}
inline void poseTo(const Pose3& T, double position[3], double orientation_wxyz[4]) {
  for (int i = 0; i < 3; ++i) position[i] = T.translation()[i];
  quatToWxyz(Quat(T.linear()), orientation_wxyz);
}

inline Vec3 vec3From(const double v[3]) { return Vec3(v[0], v[1], v[2]); }
inline void vec3To(const Vec3& v, double out[3]) {
  out[0] = v.x();
  out[1] = v.y();
  out[2] = v.z();
}

template <int N>
void matrixTo(const Eigen::Matrix<double, N, N>& m, double* out) {
  for (int r = 0; r < N; ++r)
    for (int c = 0; c < N; ++c) out[r * N + c] = m(r, c);
}
template <int N>
Eigen::Matrix<double, N, N> matrixFrom(const double* in) {
  Eigen::Matrix<double, N, N> m;
  for (int r = 0; r < N; ++r)
    for (int c = 0; c < N; ++c) m(r, c) = in[r * N + c];
  return m;
}

inline bool allFinite(const double* v, int n) {
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

}  // namespace livo
