#include "livo/inertial_window.hpp"

namespace livo {

std::set<const double*> addOldestInertialFactors(Marginalizer* m, const InertialBlocks& a, const InertialBlocks& b,
                                                 const ceres::CostFunction* imu, const ceres::CostFunction* bias_walk) {
  if (imu) m->addFactor(imu, imuFactorBlocks(a, b));
  if (bias_walk) m->addFactor(bias_walk, biasWalkBlocks(a, b));
  return {a.q, a.p, a.v, a.bg, a.ba};
}

}  // namespace livo
