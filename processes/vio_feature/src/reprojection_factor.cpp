#include "livo/vio_feature/reprojection_factor.hpp"

#include <Eigen/Geometry>

#include "livo/quaternion_manifold.hpp"

namespace livo::vio_feature {

namespace {

/// Analytic Jacobians (the cost of every optimisation is mostly this factor): with
/// P_Ca = [xy_a, 1] / rho, P_Ia = R_IC P_Ca + t_IC, P_W = R_a P_Ia + p_a,
/// P_Ij = R_j^T (P_W - p_j), P_Cj = R_IC^T (P_Ij - t_IC) and right perturbations R Exp(theta):
///   dP_Cj/dtheta_a = -R_IC^T R_j^T R_a [P_Ia]x,   dP_Cj/dp_a = R_IC^T R_j^T,
///   dP_Cj/dtheta_j = R_IC^T [P_Ij]x,              dP_Cj/dp_j = -R_IC^T R_j^T,
///   dP_Cj/drho = -R_IC^T R_j^T R_a R_IC P_Ca / rho.
class ReprojectionCost : public ceres::SizedCostFunction<2, 4, 3, 4, 3, 1> {
 public:
  ReprojectionCost(const Vec2& xy_a, const Vec2& xy_j, const Pose3& T_I_C, double weight)
      : ray_a_(xy_a.x(), xy_a.y(), 1.0),
        xy_j_(xy_j),
        R_IC_(T_I_C.linear()),
        t_IC_(T_I_C.translation()),
        weight_(weight) {}

  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    const Eigen::Map<const Eigen::Quaterniond> q_a(x[0]), q_j(x[2]);
    const Eigen::Map<const Vec3> p_a(x[1]), p_j(x[3]);
    const double rho = x[4][0];
    const Mat3 R_a = q_a.toRotationMatrix(), R_j = q_j.toRotationMatrix();
    const Vec3 P_Ca = ray_a_ / rho;
    const Vec3 P_Ia = R_IC_ * P_Ca + t_IC_;
    const Vec3 P_W = R_a * P_Ia + p_a;
    const Vec3 P_Ij = R_j.transpose() * (P_W - p_j);
    const Vec3 P_Cj = R_IC_.transpose() * (P_Ij - t_IC_);
    const double z = P_Cj.z();
    if (!(z > 1e-6)) return false;  // behind the camera: the step is refused
    residuals[0] = weight_ * (P_Cj.x() / z - xy_j_.x());
    residuals[1] = weight_ * (P_Cj.y() / z - xy_j_.y());
    if (!jacobians) return true;
    Eigen::Matrix<double, 2, 3> J_proj;
    J_proj << 1.0 / z, 0.0, -P_Cj.x() / (z * z), 0.0, 1.0 / z, -P_Cj.y() / (z * z);
    J_proj *= weight_;
    const Mat3 R_CI_R_jW = R_IC_.transpose() * R_j.transpose();
    using RowJ3 = Eigen::Matrix<double, 2, 3, Eigen::RowMajor>;
    using RowJ4 = Eigen::Matrix<double, 2, 4, Eigen::RowMajor>;
    if (jacobians[0]) {
      const RowJ3 J = J_proj * (-R_CI_R_jW * R_a * so3::hat(P_Ia));
      Eigen::Map<RowJ4>{jacobians[0]} = J * tangentToAmbient(x[0]);
    }
    if (jacobians[1]) Eigen::Map<RowJ3>{jacobians[1]} = J_proj * R_CI_R_jW;
    if (jacobians[2]) {
      const RowJ3 J = J_proj * (R_IC_.transpose() * so3::hat(P_Ij));
      Eigen::Map<RowJ4>{jacobians[2]} = J * tangentToAmbient(x[2]);
    }
    if (jacobians[3]) Eigen::Map<RowJ3>{jacobians[3]} = -J_proj * R_CI_R_jW;
    if (jacobians[4]) Eigen::Map<Eigen::Vector2d>{jacobians[4]} = J_proj * (R_CI_R_jW * R_a * R_IC_ * (-P_Ca / rho));
    return true;
  }

 private:
  Vec3 ray_a_;
  Vec2 xy_j_;
  Mat3 R_IC_;
  Vec3 t_IC_;
  double weight_;  // focal / sigma_px
};

struct InverseDepthPriorCost {
  double rho, weight;
  template <class T>
  bool operator()(const T* x, T* r) const {
    r[0] = T(weight) * (x[0] - T(rho));
    return true;
  }
};

}  // namespace

ceres::CostFunction* makeReprojectionFactor(const Vec2& xy_a, const Vec2& xy_j, const Pose3& T_I_C, double focal,
                                            double sigma_px) {
  return new ReprojectionCost(xy_a, xy_j, T_I_C, focal / sigma_px);
}

ceres::CostFunction* makeInverseDepthPrior(double depth, double sigma_depth) {
  return new ceres::AutoDiffCostFunction<InverseDepthPriorCost, 1, 1>(
      new InverseDepthPriorCost{1.0 / depth, depth * depth / sigma_depth});
}

Vec3 predictInCamera(const Vec2& xy_a, double rho, const Pose3& T_W_Ia, const Pose3& T_W_Ij, const Pose3& T_I_C) {
  const Vec3 p_Ca = Vec3(xy_a.x(), xy_a.y(), 1.0) / rho;
  return (T_W_Ij * T_I_C).inverse() * (T_W_Ia * T_I_C * p_Ca);
}

}  // namespace livo::vio_feature
