#include "livo/vio_feature/reprojection_factor.hpp"

#include <Eigen/Geometry>

namespace livo::vio_feature {

namespace {

struct ReprojectionCost {
  Vec3 ray_a;                  // [xy_a, 1]
  Vec2 xy_j;
  Eigen::Quaterniond q_IC;
  Vec3 t_IC;
  double weight;               // focal / sigma_px

  template <class T>
  bool operator()(const T* q_a, const T* p_a, const T* q_j, const T* p_j, const T* rho, T* r) const {
    using Vec3T = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Eigen::Quaternion<T>> Q_a(q_a), Q_j(q_j);
    const Eigen::Map<const Vec3T> P_a(p_a), P_j(p_j);
    const Eigen::Quaternion<T> Q_IC = q_IC.cast<T>();
    const Vec3T t = t_IC.cast<T>();
    const Vec3T p_Ca = ray_a.cast<T>() / rho[0];
    const Vec3T p_W = Q_a * Vec3T(Q_IC * p_Ca + t) + P_a;
    const Vec3T p_Ij = Q_j.conjugate() * Vec3T(p_W - P_j);
    const Vec3T p_Cj = Q_IC.conjugate() * Vec3T(p_Ij - t);
    if (!(p_Cj.z() > T(1e-6))) return false;  // behind the camera: the step is refused
    r[0] = T(weight) * (p_Cj.x() / p_Cj.z() - T(xy_j.x()));
    r[1] = T(weight) * (p_Cj.y() / p_Cj.z() - T(xy_j.y()));
    return true;
  }
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
  return new ceres::AutoDiffCostFunction<ReprojectionCost, 2, 4, 3, 4, 3, 1>(
      new ReprojectionCost{Vec3(xy_a.x(), xy_a.y(), 1.0), xy_j, Eigen::Quaterniond(T_I_C.linear()).normalized(),
                           T_I_C.translation(), focal / sigma_px});
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
