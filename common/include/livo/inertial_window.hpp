// What the inertial sliding windows of livo-lio-graph and livo-vio-feature share around their
// states: a state's parameter blocks, the blocks of the factors between two consecutive states
// (IMU preintegration, bias random walk), and those factors' part in marginalising the oldest state.
#pragma once

#include <set>
#include <vector>

#include "livo/marginalization.hpp"

namespace livo {

/// One state's parameter blocks: rotation (quaternion x y z w), position, velocity, gyro and
/// accelerometer biases.
struct InertialBlocks {
  double* q;
  double* p;
  double* v;
  double* bg;
  double* ba;
};

/// The blocks of the IMU preintegration factor from state a to b, in makeImuFactor's order.
inline std::vector<double*> imuFactorBlocks(const InertialBlocks& a, const InertialBlocks& b) {
  return {a.q, a.p, a.v, a.bg, a.ba, b.q, b.p, b.v};
}

/// The blocks of the bias random walk from state a to b, in makeBiasWalkFactor's order.
inline std::vector<double*> biasWalkBlocks(const InertialBlocks& a, const InertialBlocks& b) {
  return {a.bg, a.ba, b.bg, b.ba};
}

/// Adds to `m` the inertial factors that tie the oldest state a to the next one b: the IMU
/// preintegration and the bias walk (either may be null). Returns a's blocks: what the
/// marginalisation drops with a (the caller adds what else leaves with it).
std::set<const double*> addOldestInertialFactors(Marginalizer* m, const InertialBlocks& a, const InertialBlocks& b,
                                                 const ceres::CostFunction* imu, const ceres::CostFunction* bias_walk);

}  // namespace livo
