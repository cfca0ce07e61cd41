#include "livo/graph_factors.hpp"

namespace livo {

namespace {

using Quatd = Eigen::Quaterniond;

struct ImuCost {
  ImuPreintegration pre;
  Vec3 gravity;
  Eigen::Matrix<double, 9, 9> sqrt_info;
  template <class T>
  bool operator()(const T* q_i, const T* p_i, const T* v_i, const T* bg_i, const T* ba_i, const T* q_j, const T* p_j,
                  const T* v_j, T* r) const {
    T raw[9];
    pre.residual(q_i, p_i, v_i, bg_i, ba_i, q_j, p_j, v_j, gravity, raw);
    Eigen::Map<Eigen::Matrix<T, 9, 1>> out(r);
    out = sqrt_info.cast<T>() * Eigen::Map<const Eigen::Matrix<T, 9, 1>>(raw);
    return true;
  }
};

struct BiasWalkCost {
  Eigen::Matrix<double, 6, 1> sqrt_info;  // diagonal
  template <class T>
  bool operator()(const T* bg_i, const T* ba_i, const T* bg_j, const T* ba_j, T* r) const {
    for (int k = 0; k < 3; ++k) {
      r[k] = T(sqrt_info(k)) * (bg_j[k] - bg_i[k]);
      r[3 + k] = T(sqrt_info(3 + k)) * (ba_j[k] - ba_i[k]);
    }
    return true;
  }
};

struct PoseCost {
  Quatd q_measured_inverse;
  Vec3 p_measured;
  Mat6 sqrt_info;
  template <class T>
  bool operator()(const T* q, const T* p, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> qq(q);
    Eigen::Matrix<T, 6, 1> e;
    e.template head<3>() = quaternionLog(Eigen::Quaternion<T>(q_measured_inverse.cast<T>() * qq));
    for (int k = 0; k < 3; ++k) e(3 + k) = p[k] - T(p_measured(k));
    Eigen::Map<Eigen::Matrix<T, 6, 1>> out_map(r);
    out_map = sqrt_info.cast<T>() * e;
    return true;
  }
};

struct RelativePoseCost {
  Quatd q_measured_inverse;
  Vec3 p_measured;
  Mat6 sqrt_info;
  template <class T>
  bool operator()(const T* q_i, const T* p_i, const T* q_j, const T* p_j, T* r) const {
    const T unit(1.0);
    return (*this)(q_i, p_i, q_j, p_j, &unit, r);
  }
  template <class T>
  bool operator()(const T* q_i, const T* p_i, const T* q_j, const T* p_j, const T* scale, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> qi(q_i), qj(q_j);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> pi(p_i), pj(p_j);
    const Eigen::Quaternion<T> qi_inv = qi.conjugate();
    Eigen::Matrix<T, 6, 1> e;
    e.template head<3>() = quaternionLog(Eigen::Quaternion<T>(q_measured_inverse.cast<T>() * qi_inv * qj));
    e.template tail<3>() = qi_inv * (pj - pi) - *scale * p_measured.cast<T>();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> out_map(r);
    out_map = sqrt_info.cast<T>() * e;
    return true;
  }
};

template <int N>
struct VectorPriorCost {
  Eigen::Matrix<double, N, 1> mean, inv_sigma;
  template <class T>
  bool operator()(const T* x, T* r) const {
    for (int k = 0; k < N; ++k) r[k] = T(inv_sigma(k)) * (x[k] - T(mean(k)));
    return true;
  }
};

struct FullVectorPriorCost {
  Vec3 mean;
  Mat3 sqrt_info;  // S with S^T S = covariance^-1
  template <class T>
  bool operator()(const T* x, T* r) const {
    const Eigen::Matrix<T, 3, 1> e = Eigen::Map<const Eigen::Matrix<T, 3, 1>>(x) - mean.cast<T>();
    Eigen::Map<Eigen::Matrix<T, 3, 1>> out(r);
    out = sqrt_info.cast<T>() * e;
    return true;
  }
};

struct WheelCost {
  WheelPreintegration pre;
  Mat6 sqrt_info;
  template <class T>
  bool operator()(const T* q_i, const T* p_i, const T* q_j, const T* p_j, T* r) const {
    const T unit[2] = {T(1.0), T(1.0)};
    return (*this)(q_i, p_i, q_j, p_j, unit, r);
  }
  template <class T>
  bool operator()(const T* q_i, const T* p_i, const T* q_j, const T* p_j, const T* scale, T* r) const {
    T raw[6];
    pre.residual(q_i, p_i, q_j, p_j, scale, raw);
    Eigen::Map<Eigen::Matrix<T, 6, 1>> out_map(r);
    out_map = sqrt_info.cast<T>() * Eigen::Map<const Eigen::Matrix<T, 6, 1>>(raw);
    return true;
  }
};

/// The wheel factor through a mounting correction δ (the last block), with or without the scales.
struct MountedWheelCost {
  WheelPreintegration pre;
  Mat6 sqrt_info;
  template <class T>
  bool operator()(const T* q_i, const T* p_i, const T* q_j, const T* p_j, const T* mounting, T* r) const {
    const T unit[2] = {T(1.0), T(1.0)};
    return (*this)(q_i, p_i, q_j, p_j, unit, mounting, r);
  }
  template <class T>
  bool operator()(const T* q_i, const T* p_i, const T* q_j, const T* p_j, const T* scale, const T* mounting,
                  T* r) const {
    T raw[6];
    pre.residual(q_i, p_i, q_j, p_j, scale, mounting, raw);
    Eigen::Map<Eigen::Matrix<T, 6, 1>> out_map(r);
    out_map = sqrt_info.cast<T>() * Eigen::Map<const Eigen::Matrix<T, 6, 1>>(raw);
    return true;
  }
};

}  // namespace

ceres::Problem::Options nonOwningProblemOptions() {
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return po;
}

void solveWindow(ceres::Problem* problem, int iterations) {
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_SCHUR;
  so.max_num_iterations = iterations;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, problem, &summary);
}

ceres::CostFunction* makeImuFactor(const ImuPreintegration& preintegration, const Vec3& gravity_W) {
  return new ceres::AutoDiffCostFunction<ImuCost, 9, 4, 3, 3, 3, 3, 4, 3, 3>(
      new ImuCost{preintegration, gravity_W, preintegration.sqrtInformation()});
}

ceres::CostFunction* makeBiasWalkFactor(double gyro_random_walk, double accel_random_walk, double dt) {
  const double dt_s = std::max(dt, 1e-6);
  Eigen::Matrix<double, 6, 1> s;
  s.head<3>().setConstant(1.0 / (gyro_random_walk * std::sqrt(dt_s)));
  s.tail<3>().setConstant(1.0 / (accel_random_walk * std::sqrt(dt_s)));
  return new ceres::AutoDiffCostFunction<BiasWalkCost, 6, 3, 3, 3, 3>(new BiasWalkCost{s});
}

ceres::CostFunction* makePoseFactor(const Pose3& measured, const Mat6& information) {
  return new ceres::AutoDiffCostFunction<PoseCost, 6, 4, 3>(new PoseCost{
      Quatd(measured.linear()).normalized().inverse(), measured.translation(), Mat6(sqrtInformation(information))});
}

ceres::CostFunction* makeRelativePoseFactor(const Pose3& T_i_j, const Mat6& information) {
  return new ceres::AutoDiffCostFunction<RelativePoseCost, 6, 4, 3, 4, 3>(new RelativePoseCost{
      Quatd(T_i_j.linear()).normalized().inverse(), T_i_j.translation(), Mat6(sqrtInformation(information))});
}

ceres::CostFunction* makeScaledRelativePoseFactor(const Pose3& T_i_j, const Mat6& information) {
  return new ceres::AutoDiffCostFunction<RelativePoseCost, 6, 4, 3, 4, 3, 1>(new RelativePoseCost{
      Quatd(T_i_j.linear()).normalized().inverse(), T_i_j.translation(), Mat6(sqrtInformation(information))});
}

ceres::CostFunction* makeScalarPriorFactor(double mean, double sigma) {
  return new ceres::AutoDiffCostFunction<VectorPriorCost<1>, 1, 1>(
      new VectorPriorCost<1>{Eigen::Matrix<double, 1, 1>(mean), Eigen::Matrix<double, 1, 1>(1.0 / sigma)});
}

ceres::CostFunction* makeVectorPriorFactor(const Vec3& mean, const Vec3& sigma) {
  return new ceres::AutoDiffCostFunction<VectorPriorCost<3>, 3, 3>(new VectorPriorCost<3>{mean, sigma.cwiseInverse()});
}

ceres::CostFunction* makeCorrelatedVectorPriorFactor(const Vec3& mean, const Mat3& covariance) {
  return new ceres::AutoDiffCostFunction<FullVectorPriorCost, 3, 3>(
      new FullVectorPriorCost{mean, Mat3(sqrtInformation(covariance.inverse()))});
}

ceres::CostFunction* makeWheelScalePrior(const Vec2& mean, double sigma) {
  return new ceres::AutoDiffCostFunction<VectorPriorCost<2>, 2, 2>(
      new VectorPriorCost<2>{mean, Vec2::Constant(1.0 / sigma)});
}

ceres::CostFunction* makeWheelMountingPrior(const Vec3& mean, double sigma) {
  return makeVectorPriorFactor(mean, Vec3::Constant(sigma));
}

ceres::CostFunction* makeWheelFactor(const WheelPreintegration& preintegration) {
  return new ceres::AutoDiffCostFunction<WheelCost, 6, 4, 3, 4, 3>(
      new WheelCost{preintegration, preintegration.sqrtInformation()});
}

ceres::CostFunction* makeScaledWheelFactor(const WheelPreintegration& preintegration) {
  return new ceres::AutoDiffCostFunction<WheelCost, 6, 4, 3, 4, 3, 2>(
      new WheelCost{preintegration, preintegration.sqrtInformation()});
}

ceres::CostFunction* makeWheelFactor(const WheelPreintegration& preintegration, const WheelCalibrationBlocks& what) {
  if (!what.mounting) return what.scales ? makeScaledWheelFactor(preintegration) : makeWheelFactor(preintegration);
  auto* cost = new MountedWheelCost{preintegration, preintegration.sqrtInformation()};
  if (what.scales) return new ceres::AutoDiffCostFunction<MountedWheelCost, 6, 4, 3, 4, 3, 2, 3>(cost);
  return new ceres::AutoDiffCostFunction<MountedWheelCost, 6, 4, 3, 4, 3, 3>(cost);
}

}  // namespace livo
