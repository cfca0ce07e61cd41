// Textbook dense algebra for the tests' reference computations, on dynamic-size matrices and
// compiled once (reference_algebra.cpp). Each fixed size of an Eigen decomposition is a template
// instantiation of its own: written inline on Mat6, Mat13 and the 32-state covariance they cost
// test_esikf_update.cpp three minutes of compile time, most of the CI build's longest file.
#pragma once

#include <Eigen/Core>

namespace livo::test {

struct SymmetricEigen {
  Eigen::VectorXd values;   // ascending
  Eigen::MatrixXd vectors;  // columns, orthonormal
};

/// Eigen-decomposition of a symmetric matrix (its lower triangle is read).
SymmetricEigen symmetricEigen(const Eigen::MatrixXd& A);
/// The smallest and largest eigenvalue of a symmetric matrix.
double minEigenvalue(const Eigen::MatrixXd& A);
double maxEigenvalue(const Eigen::MatrixXd& A);
/// The numerical rank (full-pivoting LU, Eigen's default threshold).
int rankOf(const Eigen::MatrixXd& A);
/// L of A = L L^T for a symmetric positive-definite A.
Eigen::MatrixXd choleskyFactor(const Eigen::MatrixXd& A);
/// A^-1 (partial-pivoting LU).
Eigen::MatrixXd inverseOf(const Eigen::MatrixXd& A);
/// X with A X = B for a symmetric positive (semi-)definite A (LDL^T).
Eigen::MatrixXd solveSymmetric(const Eigen::MatrixXd& A, const Eigen::MatrixXd& b);
/// The minimum-norm least-squares x of A x = b (complete orthogonal decomposition).
Eigen::VectorXd minimumNormSolution(const Eigen::MatrixXd& A, const Eigen::VectorXd& b);
/// The orthogonal Q of A = Q R (Householder).
Eigen::MatrixXd orthogonalFactor(const Eigen::MatrixXd& A);

}  // namespace livo::test
