#include "livo/lio/degeneracy.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>

namespace livo::lio {

DegeneracyReport analyzeDegeneracy(const Mat6& geometry, double threshold) {
  DegeneracyReport r;
  if (!geometry.allFinite()) {
    r.degenerate = true;
    r.degenerate_rotations = r.degenerate_translations = 3;
    return r;
  }
  const Mat6 G = 0.5 * (geometry + geometry.transpose());
  Eigen::SelfAdjointEigenSolver<Mat3> rot, trans;
  rot.computeDirect(G.topLeftCorner<3, 3>());
  trans.computeDirect(G.bottomRightCorner<3, 3>());
  r.rotation_eigenvalues = rot.eigenvalues();
  r.translation_eigenvalues = trans.eigenvalues();
  r.rotation_directions = rot.eigenvectors();
  r.translation_directions = trans.eigenvectors();
  for (int i = 0; i < 3; ++i) {
    r.degenerate_rotations += r.rotation_eigenvalues[i] < threshold ? 1 : 0;
    r.degenerate_translations += r.translation_eigenvalues[i] < threshold ? 1 : 0;
  }
  r.degenerate = r.degenerate_rotations + r.degenerate_translations > 0;
  if (r.translation_eigenvalues[0] <= r.rotation_eigenvalues[0]) {
    r.min_eigenvalue = r.translation_eigenvalues[0];
    r.weakest_direction << Vec3::Zero(), r.translation_directions.col(0);
  } else {
    r.min_eigenvalue = r.rotation_eigenvalues[0];
    r.weakest_direction << r.rotation_directions.col(0), Vec3::Zero();
  }
  return r;
}

void removeDegenerateInformation(const DegeneracyReport& report, Mat6* S, Vec6* g) {
  if (!report.degenerate) return;
  // an orthonormal basis of the pose's tangent space: the degenerate directions first (m of them),
  // then the rest, each block's directions from its own eigenvectors
  const int m = report.degenerate_rotations + report.degenerate_translations;
  if (m == 6) {
    S->setZero();
    g->setZero();
    return;
  }
  Mat6 U = Mat6::Zero();
  int col = 0;
  for (int i = 0; i < report.degenerate_rotations; ++i) U.block<3, 1>(0, col++) = report.rotation_directions.col(i);
  for (int i = 0; i < report.degenerate_translations; ++i)
    U.block<3, 1>(3, col++) = report.translation_directions.col(i);
  for (int i = report.degenerate_rotations; i < 3; ++i) U.block<3, 1>(0, col++) = report.rotation_directions.col(i);
  for (int i = report.degenerate_translations; i < 3; ++i)
    U.block<3, 1>(3, col++) = report.translation_directions.col(i);
  const Mat6 Su = U.transpose() * (*S) * U;
  const Vec6 gu = U.transpose() * (*g);
  // the degenerate block's pseudo-inverse: it may hold nothing at all
  const Eigen::MatrixXd Sdd = Su.topLeftCorner(m, m);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Sdd);
  const double tol = 1e-12 * std::max(1.0, Su.diagonal().cwiseAbs().maxCoeff());
  Eigen::VectorXd inverse = es.eigenvalues();
  for (int i = 0; i < m; ++i) inverse[i] = inverse[i] > tol ? 1.0 / inverse[i] : 0.0;
  const Eigen::MatrixXd K =
      Su.bottomLeftCorner(6 - m, m) * es.eigenvectors() * inverse.asDiagonal() * es.eigenvectors().transpose();
  // the Schur complement: what the rows say about the rest with the degenerate directions free
  const Eigen::MatrixXd S_rest = Su.bottomRightCorner(6 - m, 6 - m) - K * Su.topRightCorner(m, 6 - m);
  const Eigen::VectorXd g_rest = gu.tail(6 - m) - K * gu.head(m);
  const Eigen::MatrixXd U_rest = U.rightCols(6 - m);
  *S = U_rest * (0.5 * (S_rest + S_rest.transpose())) * U_rest.transpose();
  *g = U_rest * g_rest;
}

}  // namespace livo::lio
