#include "livo/lio/degeneracy.hpp"

#include <Eigen/Eigenvalues>

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
  Mat6 Q = Mat6::Identity();
  for (int i = 0; i < report.degenerate_rotations; ++i) {
    const Vec3 e = report.rotation_directions.col(i);
    Q.topLeftCorner<3, 3>() -= e * e.transpose();
  }
  for (int i = 0; i < report.degenerate_translations; ++i) {
    const Vec3 e = report.translation_directions.col(i);
    Q.bottomRightCorner<3, 3>() -= e * e.transpose();
  }
  *S = Q * (*S) * Q;
  *g = Q * (*g);
}

}  // namespace livo::lio
