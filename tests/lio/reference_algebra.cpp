#include "reference_algebra.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>

namespace livo::test {

SymmetricEigen symmetricEigen(const Eigen::MatrixXd& A) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A);
  return {es.eigenvalues(), es.eigenvectors()};
}

double minEigenvalue(const Eigen::MatrixXd& A) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A, Eigen::EigenvaluesOnly).eigenvalues().minCoeff();
}

double maxEigenvalue(const Eigen::MatrixXd& A) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
}

int rankOf(const Eigen::MatrixXd& A) { return static_cast<int>(Eigen::FullPivLU<Eigen::MatrixXd>(A).rank()); }

Eigen::MatrixXd choleskyFactor(const Eigen::MatrixXd& A) { return Eigen::LLT<Eigen::MatrixXd>(A).matrixL(); }

Eigen::MatrixXd inverseOf(const Eigen::MatrixXd& A) { return Eigen::PartialPivLU<Eigen::MatrixXd>(A).inverse(); }

Eigen::MatrixXd solveSymmetric(const Eigen::MatrixXd& A, const Eigen::MatrixXd& b) {
  return Eigen::LDLT<Eigen::MatrixXd>(A).solve(b);
}

Eigen::VectorXd minimumNormSolution(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
  return Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(A).solve(b);
}

Eigen::MatrixXd orthogonalFactor(const Eigen::MatrixXd& A) {
  return Eigen::HouseholderQR<Eigen::MatrixXd>(A).householderQ();
}

}  // namespace livo::test
