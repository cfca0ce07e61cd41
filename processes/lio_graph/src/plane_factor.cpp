#include "livo/lio_graph/plane_factor.hpp"

#include <cmath>

namespace livo::lio_graph {

namespace {

struct PlaneCost {
  Vec3 anchor, t1, t2;  // t1, t2: orthonormal, orthogonal to the measured normal
  double offset;        // measured d_m
  double w_angle, w_distance;
  template <class T>
  bool operator()(const T* q, const T* p, const T* c, T* r) const {
    using std::sqrt;
    const Eigen::Map<const Eigen::Quaternion<T>> Q(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> P(p), C(c);
    const T len = sqrt(C.squaredNorm());
    const Eigen::Matrix<T, 3, 1> n_w = C / len;
    // world plane n_w.x + d_w = 0 with d_w = -(n_w.a) - |c|: the anchor on its negative side;
    // seen from the body (the same side as the anchor) the sensor-positive plane is its negative
    const T d_w = -n_w.dot(anchor.cast<T>()) - len;
    const Eigen::Matrix<T, 3, 1> n_b = -(Q.conjugate() * n_w);
    const T d_b = -(d_w + n_w.dot(P));
    r[0] = T(w_angle) * n_b.dot(t1.cast<T>());
    r[1] = T(w_angle) * n_b.dot(t2.cast<T>());
    r[2] = T(w_distance) * (d_b - T(offset));
    return true;
  }
};

}  // namespace

ceres::CostFunction* makePlaneFactor(const Vec3& anchor, const Vec3& measured_normal, double measured_offset,
                                     double sigma_angle, double sigma_distance) {
  const Vec3 n = measured_normal.normalized();
  const Vec3 t1 = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
  const Vec3 t2 = n.cross(t1);
  return new ceres::AutoDiffCostFunction<PlaneCost, 3, 4, 3, 3>(
      new PlaneCost{anchor, t1, t2, measured_offset, 1.0 / sigma_angle, 1.0 / sigma_distance});
}

}  // namespace livo::lio_graph
