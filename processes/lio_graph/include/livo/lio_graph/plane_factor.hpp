// The adaptive planar factor of the graph (graph_factors.hpp has the inertial, wheel and pose
// factors it shares with livo-vio-feature): a plane landmark of the window seen from a state.
#pragma once

#include <ceres/ceres.h>

#include "livo/so3.hpp"

namespace livo::lio_graph {

/// A plane landmark seen from a state (3 residuals; blocks q p c). The landmark is the vector c
/// from its anchor a (the position it was first seen from) to the plane's closest point: plane
/// n.(x - a) = |c| with n = c / |c|; never near c = 0, since no plane is seen at zero range. The
/// measurement is the plane in the body frame (n_m.x + d_m = 0, the sensor on its positive side):
/// residuals are the predicted normal along two directions orthogonal to n_m, over sigma_angle
/// (rad), and the predicted offset minus d_m, over sigma_distance (m).
ceres::CostFunction* makePlaneFactor(const Vec3& anchor, const Vec3& measured_normal, double measured_offset,
                                     double sigma_angle, double sigma_distance);

}  // namespace livo::lio_graph
