#include "livo/vio/photometric_residual.hpp"

#include <algorithm>
#include <cmath>

namespace livo::vio {

Mat26 pixelPoseJacobian(const Eigen::Matrix<double, 2, 3>& J_proj, const Mat3& R_W_I, const Pose3& T_I_C,
                        const Vec3& p_I) {
  // p_I = R^T (p_W - p): with R Exp(dr), p + dp:  dp_I = [p_I]x dr - R^T dp;  p_C = R_CI p_I + t_CI
  const Mat3 R_CI = T_I_C.linear().transpose();
  Eigen::Matrix<double, 3, 6> dpC;
  dpC.leftCols<3>() = R_CI * so3::hat(p_I);
  dpC.rightCols<3>() = -R_CI * R_W_I.transpose();
  return J_proj * dpC;
}

Mat26 pixelPoseJacobian(const ShutterProjection& s, const RollingShutter& shutter, const Pose3& T_I_C) {
  // the row's pose R Exp(ω dt): R Exp(δθ) Exp(ω dt) = R Exp(ω dt) Exp(Exp(ω dt)^T δθ), p + δp + v dt
  Mat26 B = pixelPoseJacobian(s.J_proj, s.R_W_I, T_I_C, s.p_I);
  if (s.dt != 0.0) B.leftCols<3>() *= shutter.rotationSince(s.dt).transpose();
  return B;
}

bool evaluatePatch(const ImagePyramid& pyramid, int level, const CameraProjection& camera, const Pose3& T_I_C,
                   const FilterState& x, const TrackedPatch& patch, const PhotometricOptions& o, PatchResidual* out,
                   const RollingShutter& shutter) {
  ShutterProjection s;
  if (!projectThroughShutter(camera, T_I_C, x, shutter, patch.p_W, &s)) return false;
  out->pixel = s.pixel;
  float w[kWindow * kWindow];
  if (!pyramid.sampleGrid(level, ImagePyramid::toLevel(out->pixel, level), kWindow, w)) return false;
  out->B = pixelPoseJacobian(s, shutter, T_I_C) * (1.0 / static_cast<double>(1 << level));
  // p_C = Exp(-φ) (p_C0 - ρ): d p_C / d φ = [p_C]x, d p_C / d ρ = -I
  const double scale = 1.0 / static_cast<double>(1 << level);
  out->Bc.leftCols<3>() = s.J_proj * so3::hat(s.p_C) * scale;
  out->Bc.rightCols<3>() = -s.J_proj * scale;

  const float* Q = patch.reference.data() + static_cast<size_t>(level) * kPatchArea;
  // current intensities and gradients on the 8x8 interior of the 10x10 window: the per-pixel
  // arithmetic in fixed-size rows the compiler vectorises, the sums after it in the original
  // pixel order (a floating-point sum depends on its order)
  double I[kPatchArea];
  double* Gx = out->G.col(0).data();
  double* Gy = out->G.col(1).data();
  for (int j = 0; j < kPatch; ++j) {
    const float* c = w + (j + 1) * kWindow + 1;
#pragma GCC unroll 8
    for (int i = 0; i < kPatch; ++i) {
      const int k = j * kPatch + i;
      I[k] = c[i];
      Gx[k] = 0.5 * (c[i + 1] - c[i - 1]);
      Gy[k] = 0.5 * (c[i + kWindow] - c[i - kWindow]);
    }
  }
  double sum_i = 0.0, sum_q = 0.0;
  for (int k = 0; k < kPatchArea; ++k) {
    sum_i += I[k];
    sum_q += Q[k];
  }
  const double mean_i = sum_i / kPatchArea, mean_q = sum_q / kPatchArea;
  double q[kPatchArea], di[kPatchArea];
  for (int k = 0; k < kPatchArea; ++k) {
    q[k] = Q[k] - mean_q;
    di[k] = I[k] - mean_i;
  }
  double sqq = 0.0, sii = 0.0, sqi = 0.0;
  for (int k = 0; k < kPatchArea; ++k) {
    sqq += q[k] * q[k];
    sii += di[k] * di[k];
    sqi += q[k] * di[k];
  }
  out->ncc = sqq > 1e-9 && sii > 1e-9 ? sqi / std::sqrt(sqq * sii) : 0.0;
  // brightness fit: gain free within bounds (projection onto span{q, 1}), else offset only
  const double g0 = patch.gain0, lo = o.min_gain * g0, hi = o.max_gain * g0;
  bool gain_free = false;
  double a = g0;
  if (o.affine_brightness && sqq > 1e-6 * kPatchArea) {
    a = sqi / sqq;
    gain_free = a >= lo && a <= hi;
    a = std::clamp(a, lo, hi);
  }
  out->gain = a;
  out->offset = mean_i - a * mean_q;
  for (int k = 0; k < kPatchArea; ++k) out->r[k] = I[k] - a * Q[k] - out->offset;
  // project the fit out of the gradients: G - 1 mean(G) [- q (q^T G) / q^T q]
  const Eigen::RowVector2d mean_g = out->G.colwise().mean();
  out->G.rowwise() -= mean_g;
  if (gain_free) {
    const Eigen::Map<const Eigen::Matrix<double, kPatchArea, 1>> qv(q);
    const Eigen::RowVector2d qG = qv.transpose() * out->G / sqq;
    out->G -= qv * qG;
  }
  return true;
}

namespace {
// One residual's Huber cost; accumulate()'s sum is huberCost()'s, bit for bit (the direct update
// reuses it as such).
inline double huberTerm(double a, double d) { return a <= d ? 0.5 * a * a : d * (a - 0.5 * d); }
}  // namespace

double huberCost(const PatchResidual& e, double d) {
  double cost = 0.0;
  for (int k = 0; k < kPatchArea; ++k) cost += huberTerm(std::abs(e.r[k]), d);
  return cost;
}

namespace {
double accumulateTerms(const PatchResidual& e, const PhotometricOptions& o, PoseInformation* info, const Vec6* motion,
                       CalibrationInformation* ci) {
  const double d = o.huber_threshold;
  Eigen::Matrix2d M = Eigen::Matrix2d::Zero();
  Eigen::Vector2d v = Eigen::Vector2d::Zero();
  double cost = 0.0;
  for (int k = 0; k < kPatchArea; ++k) {
    const double r = e.r[k], a = std::abs(r);
    const double wk = a <= d ? 1.0 : d / a;
    cost += huberTerm(a, d);
    const double gx = e.G(k, 0), gy = e.G(k, 1);
    M(0, 0) += wk * gx * gx;
    M(0, 1) += wk * gx * gy;
    M(1, 1) += wk * gy * gy;
    v.x() += wk * gx * r;
    v.y() += wk * gy * r;
  }
  M(1, 0) = M(0, 1);
  const double inv_var = 1.0 / (o.noise_std * o.noise_std);
  const Mat6 H = e.B.transpose() * M * e.B;
  info->HtRinvH += inv_var * H;
  info->HtRinvz += inv_var * (e.B.transpose() * v);
  info->geometry += H;
  info->count += kPatchArea;
  if (ci) {
    Eigen::Matrix<double, 2, kCalibrationDim> Bc;
    Bc.leftCols<6>() = e.Bc;
    Bc.col(6) = e.B * *motion;
    ci->S_xc += inv_var * (e.B.transpose() * M * Bc);
    ci->S_cc += inv_var * (Bc.transpose() * M * Bc);
    ci->g_c += inv_var * (Bc.transpose() * v);
  }
  return cost;
}
}  // namespace

double accumulate(const PatchResidual& e, const PhotometricOptions& o, PoseInformation* info) {
  return accumulateTerms(e, o, info, nullptr, nullptr);
}

double accumulate(const PatchResidual& e, const PhotometricOptions& o, PoseInformation* info, const Vec6& motion,
                  CalibrationInformation* ci) {
  return accumulateTerms(e, o, info, &motion, ci);
}

}  // namespace livo::vio
