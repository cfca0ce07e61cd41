#include "livo/esikf_update.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace livo {

void informationStep(const FilterState& x, const FilterState& prior, const Mat18& P_prior, const Mat6& S,
                     const Vec6& g, Vec18* delta, Mat18* P_post, const Vec18* estimated) {
  using S18 = FilterState;
  // J^-1 of eq. (12): the right Jacobian on the rotation block, identity elsewhere.
  const Vec18 e0 = x.boxminus(prior);
  const Mat3 Jr = so3::rightJacobian(e0.segment<3>(S18::kRot));
  Mat18 P = P_prior;
  // P = J^-1 P̂ J^-T touching only the rotation rows and columns
  P.topRows<3>() = Jr * P.topRows<3>();
  P.leftCols<3>() = P.leftCols<3>() * Jr.transpose();
  Vec18 Jinv_e0 = e0;
  Jinv_e0.head<3>() = Jr * e0.head<3>();

  // Pn = (P^-1 + E S E^T)^-1 = P - P E (I + S P66)^-1 S E^T P
  const Eigen::Matrix<double, 18, 6> PE = P.leftCols<6>();
  const Mat6 M = (Mat6::Identity() + S * P.topLeftCorner<6, 6>()).lu().solve(S);  // (I + S P66)^-1 S
  Mat18 Pn = P - PE * M * PE.transpose();
  Pn = 0.5 * (Pn + Pn.transpose());
  // K z = Pn E g;  K H = Pn E S E^T (nonzero in the first 6 columns only)
  const Eigen::Matrix<double, 18, 6> KH6 = Pn.leftCols<6>() * S;
  Vec18 d = -Pn.leftCols<6>() * g - Jinv_e0;
  d += KH6 * Jinv_e0.head<6>();
  if (estimated) {
    // K' = diag(estimated) K, with K H = Pn E S E^T and K R K^T = Pn E S E^T Pn in this form
    const auto keep = estimated->asDiagonal();
    d = keep * d;
    Mat18 I_KH = Mat18::Identity();
    I_KH.leftCols<6>() -= keep * KH6;
    const Eigen::Matrix<double, 18, 6> KS = keep * Pn.leftCols<6>();
    Pn = I_KH * P * I_KH.transpose() + KS * S * KS.transpose();
    Pn = 0.5 * (Pn + Pn.transpose());
  }
  *delta = d;
  *P_post = Pn;
}

Mat6 informationBeyondPrior(const Mat6& S, const Mat6& P_pose) {
  const Eigen::LLT<Mat6> llt(0.5 * (P_pose + P_pose.transpose()));
  if (llt.info() != Eigen::Success) return S;  // no usable prior: all of it is new
  const Mat6 L = llt.matrixL();
  const Mat6 W = L.transpose() * S * L;
  Eigen::SelfAdjointEigenSolver<Mat6> es(0.5 * (W + W.transpose()));
  const Vec6 excess = (es.eigenvalues().array() - 1.0).max(0.0).matrix();
  const Mat6 E = es.eigenvectors() * excess.asDiagonal() * es.eigenvectors().transpose();
  // L^-T E L^-1
  const Mat6 Linv = L.triangularView<Eigen::Lower>().solve(Mat6::Identity());
  const Mat6 out = Linv.transpose() * E * Linv;
  return 0.5 * (out + out.transpose());
}

void applyPoseMeasurementFloor(const Mat6& floor, Mat6* S, Vec6* g) {
  const Eigen::PartialPivLU<Mat6> lu(Mat6::Identity() + *S * floor);
  const Mat6 Sf = lu.solve(*S);
  *S = 0.5 * (Sf + Sf.transpose());
  *g = lu.solve(*g);
}

EsikfResult iteratedUpdate(const FilterState& prior, const Mat18& P_prior, const PoseMeasurement& measure,
                           const EsikfOptions& opts, FilterState* post, Mat18* P_post) {
  EsikfResult res;
  FilterState x = prior;
  Mat18 P = P_prior;
  for (int it = 0; it < opts.max_iterations; ++it) {
    PoseInformation info;
    if (!measure(x, it, &info) || info.count == 0) {
      if (it == 0) return res;  // nothing to update with
      break;                    // keep the last good iterate
    }
    Vec18 delta;
    informationStep(x, prior, P_prior, info.HtRinvH, info.HtRinvz, &delta, &P);
    if (!delta.allFinite() || !P.allFinite()) {
      res.valid = false;
      return res;
    }
    x = x.boxplus(delta);
    res.iterations = it + 1;
    res.info = info;
    res.valid = true;
    if (delta.segment<3>(0).norm() < opts.convergence_rot && delta.segment<3>(3).norm() < opts.convergence_pos) {
      res.converged = true;
      break;
    }
  }
  *post = x;
  *P_post = P;
  return res;
}

}  // namespace livo
