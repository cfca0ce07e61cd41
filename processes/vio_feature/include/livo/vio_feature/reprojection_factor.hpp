// The visual factors of livo-vio-feature's sliding window (Ceres). A feature is its inverse depth
// rho along the ray of its first observation (the anchor frame a, normalised image point xy_a):
// p_Ca = [xy_a, 1] / rho. Seen from frame j it predicts
//   p_Cj = T_C_I T_Wj^-1 T_Wa T_I_C p_Ca,   xy_j = p_Cj.xy / p_Cj.z,
// and the residual is (xy_j - measured) * focal / sigma_px: pixels over their sigma, so one robust
// loss scale fits every camera. States are blocks q (x y z w, right-perturbed) and p of
// graph_factors.hpp; the camera's extrinsic T_I_C is the rig's (not estimated).
#pragma once

#include <ceres/ceres.h>

#include "livo/so3.hpp"

namespace livo::vio_feature {

/// The observation xy_j (normalised, undistorted) of a feature anchored at xy_a in frame a
/// (2 residuals; blocks q_a p_a q_j p_j rho). `focal` converts normalised units to pixels.
ceres::CostFunction* makeReprojectionFactor(const Vec2& xy_a, const Vec2& xy_j, const Pose3& T_I_C, double focal,
                                            double sigma_px);

/// A measured depth d (m, along the anchor camera's z) of a feature as a prior on its inverse depth
/// (1 residual; block rho): (rho - 1/d) / (sigma_d / d^2), the depth's sigma carried to 1/d.
ceres::CostFunction* makeInverseDepthPrior(double depth, double sigma_depth);

/// The point p_Cj a feature predicts in frame j (the residual's model, for tests and outlier checks).
Vec3 predictInCamera(const Vec2& xy_a, double rho, const Pose3& T_W_Ia, const Pose3& T_W_Ij, const Pose3& T_I_C);

}  // namespace livo::vio_feature
