#include "livo/vio/patch.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>

namespace livo::vio {

bool extractStoredPatches(const ImagePyramid& pyramid, const Eigen::Vector2d& u0, int levels, uint8_t* out) {
  float buf[kStoredArea];
  for (int l = 0; l < levels; ++l) {
    if (!pyramid.sampleGrid(l, ImagePyramid::toLevel(u0, l), kStored, buf)) return false;
    for (int k = 0; k < kStoredArea; ++k) out[l * kStoredArea + k] = static_cast<uint8_t>(buf[k] + 0.5f);
  }
  return true;
}

bool affineWarp(const CameraProjection& camera, const Pose3& T_W_Ccur, const Pose3& T_W_Cref, const Vec3& p_W,
                const Vec3& normal_W, Eigen::Matrix2d* A) {
  Eigen::Vector2d px;
  Eigen::Matrix<double, 2, 3> Jc, Jr;
  const Mat3 R_CW_cur = T_W_Ccur.linear().transpose(), R_CW_ref = T_W_Cref.linear().transpose();
  if (!camera.projectWithJacobian(R_CW_cur * (p_W - T_W_Ccur.translation()), &px, &Jc)) return false;
  if (!camera.projectWithJacobian(R_CW_ref * (p_W - T_W_Cref.translation()), &px, &Jr)) return false;
  // tangent basis of the plane through p_W: the surface's where it is known and faces the
  // reference camera, else perpendicular to the reference ray
  const Vec3 ray = (p_W - T_W_Cref.translation()).normalized();
  const Vec3 n = std::abs(normal_W.dot(ray)) >= kMinNormalIncidence ? normal_W : ray;
  const Vec3 t1 = n.unitOrthogonal(), t2 = n.cross(t1);
  Eigen::Matrix<double, 3, 2> T;
  T << t1, t2;
  const Eigen::Matrix2d Mc = Jc * R_CW_cur * T, Mr = Jr * R_CW_ref * T;  // pixel offset per plane offset
  const double det = Mc.determinant();
  if (!(std::abs(det) > 1e-12)) return false;
  *A = Mr * Mc.inverse();
  return A->allFinite();
}

bool warpReferencePatch(const uint8_t* stored, const Eigen::Matrix2d& A, const Eigen::Vector2d& shift, float* out,
                        float* gx, float* gy) {
  // In three passes, each the scalar formula evaluated the same way per pixel: the warped
  // coordinates (vectorised), the bounds, then the bilinear samples (the four taps gathered, the
  // weighting vectorised).
  constexpr double h = 0.5 * (kPatch - 1);
  const double cx = 0.5 * (kStored - 1) + shift.x(), cy = 0.5 * (kStored - 1) + shift.y();
  const double lim = kStored - 1;
  const double a00 = A(0, 0), a01 = A(0, 1), a10 = A(1, 0), a11 = A(1, 1);
  double x[kPatchArea], y[kPatchArea];
  for (int j = 0; j < kPatch; ++j) {
#pragma GCC unroll 8
    for (int i = 0; i < kPatch; ++i) {
      const double dx = i - h, dy = j - h;
      x[j * kPatch + i] = cx + a00 * dx + a01 * dy;
      y[j * kPatch + i] = cy + a10 * dx + a11 * dy;
    }
  }
  bool inside = true;
  for (int k = 0; k < kPatchArea; ++k) inside &= x[k] >= 0.0 && y[k] >= 0.0 && x[k] <= lim && y[k] <= lim;
  if (!inside) return false;
  float ax[kPatchArea], ay[kPatchArea], v00[kPatchArea], v10[kPatchArea], v01[kPatchArea], v11[kPatchArea];
  for (int k = 0; k < kPatchArea; ++k) {
    const int ix = std::min(static_cast<int>(x[k]), kStored - 2), iy = std::min(static_cast<int>(y[k]), kStored - 2);
    ax[k] = static_cast<float>(x[k] - ix);
    ay[k] = static_cast<float>(y[k] - iy);
    const uint8_t* r0 = stored + iy * kStored + ix;
    const uint8_t* r1 = r0 + kStored;
    v00[k] = r0[0];
    v10[k] = r0[1];
    v01[k] = r1[0];
    v11[k] = r1[1];
  }
  for (int k = 0; k < kPatchArea; ++k)
    out[k] = (1 - ax[k]) * (1 - ay[k]) * v00[k] + ax[k] * (1 - ay[k]) * v10[k] + (1 - ax[k]) * ay[k] * v01[k] +
             ax[k] * ay[k] * v11[k];
  if (gx && gy)
    for (int k = 0; k < kPatchArea; ++k) {
      gx[k] = (1 - ay[k]) * (v10[k] - v00[k]) + ay[k] * (v11[k] - v01[k]);
      gy[k] = (1 - ax[k]) * (v01[k] - v00[k]) + ax[k] * (v11[k] - v10[k]);
    }
  return true;
}

float patchGradient(const ImagePyramid& pyramid, int level, const Eigen::Vector2d& u) {
  float w[kWindow * kWindow];
  if (!pyramid.sampleGrid(level, u, kWindow, w)) return -1.0f;
  float sum = 0.0f;
  for (int j = 1; j <= kPatch; ++j)
    for (int i = 1; i <= kPatch; ++i) {
      const float* p = w + j * kWindow + i;
      sum += std::abs(p[1] - p[-1]) + std::abs(p[kWindow] - p[-kWindow]);
    }
  return 0.5f * sum / kPatchArea;
}

}  // namespace livo::vio
