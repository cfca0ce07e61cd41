#include "livo/lio/keyframe_clone.hpp"

#include <vector>

#include "livo/so3.hpp"

namespace livo::lio {

Mat6 relativePoseCovariance(const Pose3& T_a, const Pose3& T_b, const Mat6& P_aa, const Mat6& P_bb, const Mat6& P_ba) {
  // R_a = R̂_a Exp(δa_r), p_a = p̂_a + δa_p (and b alike); T_rel = T_a^-1 T_b:
  //   phi = δb_r - R_rel^T δa_r
  //   tau = R_rel^T [p_rel]x δa_r + R_b^T (δb_p - δa_p)
  const Mat3 Ra = T_a.linear(), Rb = T_b.linear();
  const Mat3 R_rel = Ra.transpose() * Rb;
  const Vec3 p_rel = Ra.transpose() * (T_b.translation() - T_a.translation());
  Mat6 Ja = Mat6::Zero(), Jb = Mat6::Zero();
  Ja.topLeftCorner<3, 3>() = -R_rel.transpose();
  Ja.bottomLeftCorner<3, 3>() = R_rel.transpose() * so3::hat(p_rel);
  Ja.bottomRightCorner<3, 3>() = -Rb.transpose();
  Jb.topLeftCorner<3, 3>() = Mat3::Identity();
  Jb.bottomRightCorner<3, 3>() = Rb.transpose();
  const Mat6 cross = Jb * P_ba * Ja.transpose();
  const Mat6 cov = Ja * P_aa * Ja.transpose() + Jb * P_bb * Jb.transpose() + cross + cross.transpose();
  return 0.5 * (cov + cov.transpose());
}

Mat6 heldCalibrationCovariance(const Pose3& T_rel, const HeldCalibration& held) {
  Mat6 cov = Mat6::Zero();
  if (held.lidar_rotation_std > 0.0 || held.lidar_translation_std > 0.0) {
    const Mat6 J = (se3::adjoint(T_rel.inverse()) - Mat6::Identity()) * se3::adjoint(held.T_I_L);
    Vec6 extrinsic_var;
    extrinsic_var << Vec3::Constant(held.lidar_rotation_std * held.lidar_rotation_std),
        Vec3::Constant(held.lidar_translation_std * held.lidar_translation_std);
    cov += J * extrinsic_var.asDiagonal() * J.transpose();
  }
  if (held.gyro_scale_std > 0.0 || held.gyro_misalignment_std > 0.0) {
    const Vec3 theta = so3::Log(Mat3(T_rel.linear()));
    const Vec3 theta2 = theta.cwiseAbs2();
    const double s2 = held.gyro_scale_std * held.gyro_scale_std;
    const double m2 = held.gyro_misalignment_std * held.gyro_misalignment_std;
    // (M theta)_i = s_i theta_i + sum_{j != i} m_ij theta_j, all independent
    for (int i = 0; i < 3; ++i) cov(i, i) += s2 * theta2(i) + m2 * (theta2.sum() - theta2(i));
  }
  return cov;
}

ConditionedBeside conditionedOnUpdate(const StateCovariance& P_prior, const StateCovariance& P_post,
                                      const Eigen::MatrixXd& C, const StateVector& dx) {
  std::vector<int> idx;
  for (int i = 0; i < FilterState::kDim; ++i)
    if (P_prior(i, i) > 0.0) idx.push_back(i);
  const int n = static_cast<int>(idx.size()), m = static_cast<int>(C.cols());
  Eigen::MatrixXd Pr(n, n), Cr(n, m), Qr(n, n);
  Eigen::VectorXd dr(n);
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) {
      Pr(r, c) = P_prior(idx[r], idx[c]);
      Qr(r, c) = P_post(idx[r], idx[c]);
    }
    Cr.row(r) = C.row(idx[r]);
    dr(r) = dx(idx[r]);
  }
  // the solve over the estimated states (held ones have zero rows in C and no step), then P_post's
  // columns over them
  const Eigen::MatrixXd Y = Pr.ldlt().solve(Cr);
  ConditionedBeside out;
  out.cross = Eigen::MatrixXd::Zero(FilterState::kDim, m);
  for (int r = 0; r < FilterState::kDim; ++r)
    for (int k = 0; k < n; ++k) out.cross.row(r) += P_post(r, idx[k]) * Y.row(k);
  out.mean_step = Y.transpose() * dr;
  const Eigen::MatrixXd change = -Cr.transpose() * Y + Y.transpose() * Qr * Y;
  out.covariance_change = 0.5 * (change + change.transpose());
  return out;
}

CloneCrossCovariance carriedThroughUpdate(const StateCovariance& P_prior, const StateCovariance& P_post,
                                          const CloneCrossCovariance& C) {
  return conditionedOnUpdate(P_prior, P_post, C, StateVector::Zero()).cross;
}

}  // namespace livo::lio
