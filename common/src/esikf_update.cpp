#include "livo/esikf_update.hpp"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "livo/chi_square.hpp"

namespace livo {

namespace {
using Mat32x13 = Eigen::Matrix<double, FilterState::kDim, kMeasuredDim>;
}  // namespace

Mat13 measuredCovariance(const StateCovariance& P, int block) {
  Mat13 out;
  for (int r = 0; r < kMeasuredDim; ++r)
    for (int c = 0; c < kMeasuredDim; ++c) {
      const int i = r < 6 ? r : block + (r - 6), j = c < 6 ? c : block + (c - 6);
      out(r, c) = P(i, j);
    }
  return out;
}

void informationStep(const FilterState& x, const FilterState& prior, const StateCovariance& P_prior,
                     const MeasurementInformation& m, StateVector* delta, StateCovariance* P_post,
                     const StateVector* estimated) {
  // J^-1 of eq. (12): the right Jacobians on the rotation blocks, identity elsewhere.
  const StateVector e0 = x.boxminus(prior);
  StateCovariance P = P_prior;
  StateVector Jinv_e0 = e0;
  for (const int b : FilterState::kRotationBlocks) {
    const Mat3 Jr = so3::rightJacobian(e0.segment<3>(b));
    // P = J^-1 P̂ J^-T touching only the rotation rows and columns
    P.middleRows<3>(b) = Jr * P.middleRows<3>(b);
    P.middleCols<3>(b) = P.middleCols<3>(b) * Jr.transpose();
    Jinv_e0.segment<3>(b) = Jr * e0.segment<3>(b);
  }
  // the measured states: E picks columns [0, 6) and [block, block + 7)
  auto pick = [&](const StateCovariance& A) {
    Mat32x13 AE;
    AE.leftCols<6>() = A.leftCols<6>();
    AE.rightCols<FilterState::kCalibrationDim>() = A.middleCols<FilterState::kCalibrationDim>(m.calibration_block);
    return AE;
  };
  const Mat13& S = m.HtRinvH;
  const Mat32x13 PE = pick(P);
  const Mat13 PEE = measuredCovariance(P, m.calibration_block);
  // Pn = (P^-1 + E S E^T)^-1 = P - P E (I + S P_EE)^-1 S E^T P
  const Mat13 M = (Mat13::Identity() + S * PEE).lu().solve(S);  // (I + S P_EE)^-1 S
  StateCovariance Pn = P - PE * M * PE.transpose();
  Pn = (0.5 * (Pn + Pn.transpose())).eval();  // .eval(): the right side reads what the left writes
  // K z = Pn E g;  K H = Pn E S E^T (nonzero in the measured columns only)
  const Mat32x13 PnE = pick(Pn);
  const Mat32x13 KHE = PnE * S;
  Vec13 e0E;
  for (int k = 0; k < kMeasuredDim; ++k) e0E[k] = Jinv_e0[m.stateIndex(k)];
  StateVector d = -PnE * m.HtRinvz - Jinv_e0 + KHE * e0E;
  if (estimated) {
    // K' = diag(estimated) K, with K H = Pn E S E^T and K R K^T = Pn E S E^T Pn in this form
    const auto keep = estimated->asDiagonal();
    d = keep * d;
    StateCovariance I_KH = StateCovariance::Identity();
    const Mat32x13 kKHE = keep * KHE;
    for (int k = 0; k < kMeasuredDim; ++k) I_KH.col(m.stateIndex(k)) -= kKHE.col(k);
    const Mat32x13 KS = keep * PnE;
    Pn = I_KH * P * I_KH.transpose() + KS * S * KS.transpose();
    Pn = (0.5 * (Pn + Pn.transpose())).eval();
  }
  *delta = d;
  *P_post = Pn;
}

void informationStep(const FilterState& x, const FilterState& prior, const StateCovariance& P_prior, const Mat6& S,
                     const Vec6& g, StateVector* delta, StateCovariance* P_post, const StateVector* estimated) {
  MeasurementInformation m;
  m.HtRinvH.topLeftCorner<6, 6>() = S;
  m.HtRinvz.head<6>() = g;
  informationStep(x, prior, P_prior, m, delta, P_post, estimated);
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

namespace {
// The measured states the prior estimates (positive variance) and P's block over them.
int estimatedStates(const Mat13& P, int idx[kMeasuredDim]) {
  int n = 0;
  for (int i = 0; i < kMeasuredDim; ++i)
    if (P(i, i) > 0.0) idx[n++] = i;
  return n;
}
Eigen::MatrixXd restrict(const Mat13& A, const int* idx, int n) {
  Eigen::MatrixXd B(n, n);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) B(r, c) = A(idx[r], idx[c]);
  return B;
}
}  // namespace

void scaleCalibrationInformation(double scale, const Mat13& P_measured, MeasurementInformation* m) {
  if (scale == 1.0) return;
  // over the states the prior estimates (a state held fixed stays where it is: the measurement's
  // optimum is the one given it)
  int idx[kMeasuredDim];
  int n = 0;
  bool any_calibration = false;
  for (int i = 0; i < kMeasuredDim; ++i)
    if (P_measured(i, i) > 0.0) {
      idx[n++] = i;
      any_calibration |= i >= 6;
    }
  if (!any_calibration) return;
  Eigen::MatrixXd S(n, n);
  Eigen::VectorXd g(n);
  for (int r = 0; r < n; ++r) {
    g[r] = m->HtRinvz[idx[r]];
    for (int c = 0; c < n; ++c) S(r, c) = 0.5 * (m->HtRinvH(idx[r], idx[c]) + m->HtRinvH(idx[c], idx[r]));
  }
  // the measurement's own optimum, -S⁺ g, kept: g' = -S' (-S⁺ g) = S' S⁺ g
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(S);
  const double tiny = 1e-12 * std::max(1.0, es.eigenvalues().maxCoeff());
  Eigen::VectorXd optimum = Eigen::VectorXd::Zero(n);  // S⁺ g
  for (int i = 0; i < n; ++i)
    if (es.eigenvalues()[i] > tiny)
      optimum += es.eigenvectors().col(i) * (es.eigenvectors().col(i).dot(g) / es.eigenvalues()[i]);
  const double r = std::sqrt(scale);
  Mat13 Sd = m->HtRinvH;
  Sd.bottomRows<FilterState::kCalibrationDim>() *= r;
  Sd.rightCols<FilterState::kCalibrationDim>() *= r;
  m->HtRinvH = Sd;
  for (int a = 0; a < n; ++a) {
    double v = 0.0;
    for (int c = 0; c < n; ++c) v += Sd(idx[a], idx[c]) * optimum[c];
    m->HtRinvz[idx[a]] = v;
  }
}

Mat13 informationBeyondPrior(const Mat13& S, const Mat13& P) {
  int idx[kMeasuredDim];
  const int n = estimatedStates(P, idx);
  Mat13 out = Mat13::Zero();
  if (n == 0) return out;
  const Eigen::MatrixXd Pr = restrict(0.5 * (P + P.transpose()), idx, n), Sr = restrict(S, idx, n);
  const Eigen::LLT<Eigen::MatrixXd> llt(Pr);
  Eigen::MatrixXd B;
  if (llt.info() != Eigen::Success) {
    B = Sr;  // no usable prior: all of it is new
  } else {
    const Eigen::MatrixXd L = llt.matrixL();
    const Eigen::MatrixXd W = L.transpose() * Sr * L;
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (W + W.transpose()));
    const Eigen::VectorXd excess = (es.eigenvalues().array() - 1.0).max(0.0).matrix();
    const Eigen::MatrixXd E = es.eigenvectors() * excess.asDiagonal() * es.eigenvectors().transpose();
    const Eigen::MatrixXd Linv = L.triangularView<Eigen::Lower>().solve(Eigen::MatrixXd::Identity(n, n));
    B = Linv.transpose() * E * Linv;
  }
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) out(idx[r], idx[c]) = 0.5 * (B(r, c) + B(c, r));
  return out;
}

void applyMeasurementFloor(const Mat13& floor, Mat13* S, Vec13* g) {
  const Eigen::PartialPivLU<Mat13> lu(Mat13::Identity() + *S * floor);
  const Mat13 Sf = lu.solve(*S);
  *S = 0.5 * (Sf + Sf.transpose());
  *g = lu.solve(*g);
}

ConsistencyTest consistencyTest(const Vec13& e, const Mat13& S, const Vec13& g, const Mat13& P, double probability,
                                double min_information) {
  ConsistencyTest t;
  int idx[kMeasuredDim];
  const int n = estimatedStates(P, idx);
  if (n == 0) return t;
  const Eigen::LLT<Eigen::MatrixXd> llt(restrict(0.5 * (P + P.transpose()), idx, n));
  if (llt.info() != Eigen::Success) return t;
  const Eigen::MatrixXd L = llt.matrixL();
  Eigen::VectorXd er(n), gr(n);
  for (int r = 0; r < n; ++r) er[r] = e[idx[r]], gr[r] = g[idx[r]];
  const Eigen::MatrixXd W = L.transpose()* restrict(S, idx, n) * L;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (W + W.transpose()));
  // ν_w = L⁻¹ e - W⁺ Lᵀ g over the tested directions
  const Eigen::VectorXd e_w = L.triangularView<Eigen::Lower>().solve(er);
  const Eigen::VectorXd g_w = L.transpose() * gr;
  for (int i = 0; i < n; ++i) {
    const double lambda = es.eigenvalues()[i];
    if (!(lambda >= min_information)) continue;
    const Eigen::VectorXd v = es.eigenvectors().col(i);
    const double nu = v.dot(e_w) - v.dot(g_w) / lambda;
    t.nis += nu * nu * lambda / (1.0 + lambda);
    ++t.dof;
  }
  if (t.dof > 0) {
    t.threshold = chiSquareQuantile(probability, t.dof);
    t.passed = t.nis <= t.threshold;
  }
  return t;
}

EsikfResult iteratedUpdate(const FilterState& prior, const StateCovariance& P_prior, const Measurement& measure,
                           const EsikfOptions& opts, FilterState* post, StateCovariance* P_post) {
  EsikfResult res;
  FilterState x = prior;
  StateCovariance P = P_prior;
  for (int it = 0; it < opts.max_iterations; ++it) {
    MeasurementInformation info;
    if (!measure(x, it, &info) || info.count == 0) {
      if (it == 0) return res;  // nothing to update with
      break;                    // keep the last good iterate
    }
    StateVector delta;
    informationStep(x, prior, P_prior, info, &delta, &P);
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
