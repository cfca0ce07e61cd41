#include "livo/loop/loop_information.hpp"

#include <algorithm>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace livo::loop {

namespace {
Mat6 blockDiagonal(const Mat3& a, const Mat3& b) {
  Mat6 m = Mat6::Zero();
  m.topLeftCorner<3, 3>() = a;
  m.bottomRightCorner<3, 3>() = b;
  return m;
}
Mat6 symmetric(const Mat6& m) { return 0.5 * (m + m.transpose()); }

// The information without the translation directions that fewer than `fraction` of the normals
// constrain: per correspondence, the translation block of sum J^T n n^T J is the mean of n n^T
// (trace 1), whose eigenvalues are the shares of the normals along its eigenvectors. Such a
// direction is projected out, with its coupling to the rotations.
Mat6 constrainedPart(const GicpResult& fine, double fraction) {
  if (!fine.plane_information.allFinite() || fine.plane_correspondences <= 6) return Mat6::Zero();
  const Mat3 per_point =
      fine.plane_information.bottomRightCorner<3, 3>() * (fine.plane_residual_variance / fine.plane_correspondences);
  Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (per_point + per_point.transpose()));
  Mat6 P = Mat6::Identity();
  for (int i = 0; i < 3; ++i)
    if (es.eigenvalues()(i) < fraction)
      P.bottomRightCorner<3, 3>() -= es.eigenvectors().col(i) * es.eigenvectors().col(i).transpose();
  return symmetric(P * fine.plane_information * P);
}
}  // namespace

Mat6 registrationCovariance(const GicpResult& fine, const Pose3& T_target_source, const LoopInformationOptions& o) {
  // left perturbation in the target frame -> right perturbation: Exp(zeta) T = T Exp(Ad(T^-1) zeta),
  // so the information L_right = Ad(T)^T L_left Ad(T)
  const Mat6 Ad = se3::adjoint(T_target_source);
  Mat6 info = Ad.transpose() * constrainedPart(fine, o.min_constrained_fraction) * Ad;
  // the caps, in units of the cap (x = D x_n): every eigenvalue of D info D at least 1
  Vec6 cap;
  cap << Vec3::Constant(o.max_rotation_sigma), Vec3::Constant(o.max_translation_sigma);
  const Mat6 D = cap.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Mat6> es(symmetric(D * info * D));
  const Vec6 values = es.eigenvalues().cwiseMax(1.0);
  // covariance of x_n: V diag(1 / values) V^T, of x: D (...) D
  Mat6 cov = D * es.eigenvectors() * values.cwiseInverse().asDiagonal() * es.eigenvectors().transpose() * D;
  cov(0, 0) += o.roll_pitch_sigma * o.roll_pitch_sigma;
  cov(1, 1) += o.roll_pitch_sigma * o.roll_pitch_sigma;
  const double fitness_sigma = o.fitness_rotation_sigma * fine.fitness;
  for (int i = 0; i < 3; ++i) cov(i, i) += o.min_rotation_sigma * o.min_rotation_sigma + fitness_sigma * fitness_sigma;
  for (int i = 3; i < 6; ++i) cov(i, i) += o.min_translation_sigma * o.min_translation_sigma;
  return symmetric(cov);
}

Mat6 edgeCovarianceFromRight(const Pose3& T_a_b, const Mat6& cov_right) {
  // T Exp([phi; tau]) = (R Exp(phi), t + R tau) to first order: the edge's [phi; R tau]
  const Mat6 B = blockDiagonal(Mat3::Identity(), T_a_b.linear());
  return symmetric(B * cov_right * B.transpose());
}

Mat6 rightCovarianceFromEdge(const Pose3& T_a_b, const Mat6& cov_edge) {
  const Mat6 B = blockDiagonal(Mat3::Identity(), T_a_b.linear().transpose());
  return symmetric(B * cov_edge * B.transpose());
}

Mat6 composedCovariance(const Mat6& cov1, const Pose3& T2, const Mat6& cov2) {
  // T1 Exp(a) T2 Exp(b) = T1 T2 Exp(Ad(T2^-1) a + b)
  const Mat6 A = se3::adjoint(T2.inverse());
  return symmetric(A * cov1 * A.transpose() + cov2);
}

Mat6 inverseCovariance(const Pose3& T, const Mat6& cov) {
  // (T Exp(a))^-1 = Exp(-a) T^-1 = T^-1 Exp(-Ad(T) a)
  const Mat6 A = se3::adjoint(T);
  return symmetric(A * cov * A.transpose());
}

Mat6 informationFromCovariance(const Mat6& cov) { return symmetric(symmetric(cov).ldlt().solve(Mat6::Identity())); }

}  // namespace livo::loop
