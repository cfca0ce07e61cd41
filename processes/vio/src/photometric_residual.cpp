#include "livo/vio/photometric_residual.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

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

Eigen::Matrix<double, 2, kMeasuredDim> currentPixelJacobian(const ShutterProjection& s, const RollingShutter& shutter,
                                                            const FilterState& x) {
  Eigen::Matrix<double, 2, kMeasuredDim> J;
  // wrt the pose at the image's true time (stamp + the camera's time shift), then the shift's column:
  // moving that time by δ turns the body by ω δ (right) and moves it by v δ
  const Mat26 B = pixelPoseJacobian(s, shutter, x.camera.pose());
  J.leftCols<6>() = B;
  J.col(12) = B.leftCols<3>() * shutter.omega_I + B.rightCols<3>() * x.vel;
  // the state's error is at the stamp: R Exp(δθ) Exp(ω dt) = R Exp(ω dt) Exp(Exp(ω dt)^T δθ)
  if (x.camera.dt != 0.0) J.leftCols<3>() *= shutter.rotationSince(x.camera.dt).transpose();
  J.middleCols<6>(6) = pixelExtrinsicJacobian(s.J_proj, s.p_C, x.camera.rot);
  return J;
}

namespace {

// The rows of the Jacobians of the two pixels: d [current; reference] / d [δθ δp δφ δρ δdt] (B) and
// d [current; reference] / d p_W (Bp), in pixels of the level (`scale`).
void pixelJacobians(const ShutterProjection& s, const RollingShutter& shutter, const FilterState& x, const Mat27& J_ref,
                    const Eigen::Matrix<double, 2, 3>& J_ref_point, double scale, PatchResidual* out) {
  out->B.topRows<2>() = currentPixelJacobian(s, shutter, x) * scale;
  out->B.bottomRows<2>().leftCols<6>().setZero();
  out->B.bottomRows<2>().rightCols<FilterState::kCalibrationDim>() = J_ref * scale;
  // the map point moves both pixels: d u / d p_W = J_proj R_C_W of each view
  out->Bp.topRows<2>() = s.J_proj * (x.camera.rot.transpose() * s.R_W_I.transpose()) * scale;
  out->Bp.bottomRows<2>() = J_ref_point * scale;
}

// d reference pixel / d [δθ δp] of the reference's body pose (Bref, level pixels) and the baseline
// between the two camera centres.
void referencePoseJacobian(const TrackedPatch& patch, const FilterState& x, const ShutterProjection& s,
                           const Eigen::Matrix<double, 2, 3>& J_ref_point, double scale, PatchResidual* out) {
  // the reference body pose's right perturbation: p_I = R_ref^T (p_W - p_ref) as for the current view
  const double dtr = x.camera.dt - patch.view.time_shift;
  const Mat3 R_ref = dtr != 0.0 ? Mat3(patch.view.T_W_I.linear() * so3::Exp(patch.view.omega_I * dtr))
                                : Mat3(patch.view.T_W_I.linear());
  const Vec3 p_ref = patch.view.T_W_I.translation() + patch.view.vel_W * dtr;
  // d u / d p_W = J (R_C_I R_I_W): the position columns are -that, the rotation's J R_C_I [p_I]x
  const Vec3 p_Iref = R_ref.transpose() * (patch.p_W - p_ref);
  const Eigen::Matrix<double, 2, 3> J_proj_ref = J_ref_point * R_ref;  // d u / d p_I  R_I_C ... as J_proj R_C_I
  out->Bref.leftCols<3>() = J_proj_ref * so3::hat(p_Iref) * scale;
  out->Bref.rightCols<3>() = -J_ref_point * scale;
  out->baseline = (s.R_W_I * x.camera.pos + s.p_W_I - (R_ref * x.camera.pos + p_ref)).norm();
}

// The current intensities I and their gradients (G's first two columns) on the 8x8 interior of the
// sampled 10x10 window w, the reference Q at the shift ds from the sampled one (to first order) and
// d r / d s (G's last two columns).
void sampleIntensities(const float* w, const TrackedPatch& patch, int level, const Eigen::Vector2d& ds, double* I,
                       double* Q, Eigen::Matrix<double, kPatchArea, 4>* G) {
  const size_t at = static_cast<size_t>(level) * kPatchArea;
  const float* Q0 = patch.reference.data() + at;
  const float* Qx = patch.reference_dx.data() + at;
  const float* Qy = patch.reference_dy.data() + at;
  // the per-pixel arithmetic in fixed-size rows the compiler vectorises, the sums after it in the
  // original pixel order (a floating-point sum depends on its order)
  double* Gx = G->col(0).data();
  double* Gy = G->col(1).data();
  double* Rx = G->col(2).data();
  double* Ry = G->col(3).data();
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
  // the reference at the shift of this calibration, to first order from the sampled one; its
  // gradient the current image's through the warp (above): d r / d s = -a ∇Q = -A^-T ∇I
  const Eigen::Matrix2d Ainv_t = patch.warp.inverse().transpose();
  for (int k = 0; k < kPatchArea; ++k) {
    Q[k] = Q0[k] + Qx[k] * ds.x() + Qy[k] * ds.y();
    Rx[k] = -(Ainv_t(0, 0) * Gx[k] + Ainv_t(0, 1) * Gy[k]);
    Ry[k] = -(Ainv_t(1, 0) * Gx[k] + Ainv_t(1, 1) * Gy[k]);
  }
}

// The brightness fit of the reference Q to the current I (the gain free within bounds around g0,
// a projection onto span{q, 1}; else the offset only): ncc, gain, offset and the residuals r, and
// the fit projected out of every column of G.
void fitBrightness(const double* I, const double* Q, double g0, const PhotometricOptions& o, PatchResidual* out) {
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
  const double lo = o.min_gain * g0, hi = o.max_gain * g0;
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
  // the fit projected out of every column: G - 1 mean(G) [- q (q^T G) / q^T q]
  const Eigen::RowVector4d mean_g = out->G.colwise().mean();
  out->G.rowwise() -= mean_g;
  if (gain_free) {
    const Eigen::Map<const Eigen::Matrix<double, kPatchArea, 1>> qv(q);
    const Eigen::RowVector4d qG = qv.transpose() * out->G / sqq;
    out->G -= qv * qG;
  }
}

}  // namespace

bool evaluatePatch(const ImagePyramid& pyramid, int level, const CameraProjection& camera, const FilterState& x,
                   const TrackedPatch& patch, const PhotometricOptions& o, PatchResidual* out,
                   const RollingShutter& shutter) {
  const Pose3 T_I_C = x.camera.pose();
  ShutterProjection s;
  if (!projectThroughShutter(camera, T_I_C, advanced(x, shutter.omega_I, x.camera.dt), shutter, patch.p_W, &s))
    return false;
  // where the reference image sees the point through this calibration
  Eigen::Vector2d u_ref;
  Mat27 J_ref;
  Eigen::Matrix<double, 2, 3> J_ref_point;
  if (!projectIntoReference(camera, patch.view, x.camera, patch.p_W, &u_ref, &J_ref, &J_ref_point)) return false;
  const double scale = 1.0 / static_cast<double>(1 << level);
  const Eigen::Vector2d ds = (u_ref - patch.view.pixel - patch.shift0) * scale;  // from the sampled shift
  if (ds.cwiseAbs().maxCoeff() > 1.0) return false;  // first order in the shift: re-select instead
  out->pixel = s.pixel;
  float w[kWindow * kWindow];
  if (!pyramid.sampleGrid(level, ImagePyramid::toLevel(out->pixel, level), kWindow, w)) return false;
  pixelJacobians(s, shutter, x, J_ref, J_ref_point, scale, out);
  referencePoseJacobian(patch, x, s, J_ref_point, scale, out);
  double I[kPatchArea], Q[kPatchArea];
  sampleIntensities(w, patch, level, ds, I, Q, &out->G);
  fitBrightness(I, Q, patch.gain0, o, out);
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

double accumulate(const PatchResidual& e, const PhotometricOptions& o, MeasurementInformation* info) {
  const double d = o.huber_threshold;
  Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
  Eigen::Vector4d v = Eigen::Vector4d::Zero();
  double cost = 0.0;
  for (int k = 0; k < kPatchArea; ++k) {
    const double r = e.r[k], a = std::abs(r);
    const double wk = a <= d ? 1.0 : d / a;
    cost += huberTerm(a, d);
    const Eigen::Vector4d gk = e.G.row(k).transpose();
    M.noalias() += wk * gk * gk.transpose();
    v.noalias() += wk * r * gk;
  }
  const double inv_var = 1.0 / (o.noise_std * o.noise_std);
  Mat13 H = e.B.transpose() * M * e.B;
  Vec13 g = e.B.transpose() * v;
  info->geometry += H.topLeftCorner<6, 6>();
  // the nuisances with their priors, eliminated by the Schur complement of [x; n]'s information:
  // the map point (3) and the reference's body pose relative to the current one (6)
  const double rot_std = o.reference_rotation_std_deg * M_PI / 180.0;
  const double pos_std = o.reference_translation_std + o.reference_translation_per_m * e.baseline;
  if (o.point_std > 0.0 || rot_std > 0.0 || pos_std > 0.0) {
    using Mat4x9 = Eigen::Matrix<double, 4, 9>;
    using Mat9 = Eigen::Matrix<double, 9, 9>;
    Mat4x9 Bn = Mat4x9::Zero();
    Eigen::Matrix<double, 9, 1> prior = Eigen::Matrix<double, 9, 1>::Zero();  // information, in units of noise_std^-2
    const double s2 = o.noise_std * o.noise_std;
    if (o.point_std > 0.0) {
      Bn.leftCols<3>() = e.Bp;
      prior.head<3>().setConstant(s2 / (o.point_std * o.point_std));
    }
    if (rot_std > 0.0) {
      Bn.block<2, 3>(2, 3) = e.Bref.leftCols<3>();
      prior.segment<3>(3).setConstant(s2 / (rot_std * rot_std));
    }
    if (pos_std > 0.0) {
      Bn.block<2, 3>(2, 6) = e.Bref.rightCols<3>();
      prior.tail<3>().setConstant(s2 / (pos_std * pos_std));
    }
    for (int i = 0; i < 9; ++i)
      if (prior[i] == 0.0) prior[i] = 1.0;  // an unused column: no information, any prior
    const Eigen::Matrix<double, kMeasuredDim, 9> Hxn = e.B.transpose() * M * Bn;
    Mat9 Hnn = Bn.transpose() * M * Bn;
    Hnn.diagonal() += prior;
    const Eigen::LLT<Mat9> llt(Hnn);
    H -= Hxn * llt.solve(Hxn.transpose());
    g -= Hxn * llt.solve(Bn.transpose() * v);
  }
  info->calibration_block = FilterState::kCamera;
  info->HtRinvH += inv_var * H;
  info->HtRinvz += inv_var * g;
  info->count += kPatchArea;
  return cost;
}

}  // namespace livo::vio
