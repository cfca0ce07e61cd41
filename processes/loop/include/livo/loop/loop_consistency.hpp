// Whether a verified loop agrees with what the graph already knows, before it enters it (in the
// spirit of pairwise consistency maximisation, Mangelson et al. 2018, checked sequentially): the
// loop's measured relative pose against the one predicted by the odometry, and by the cycle
// through an earlier loop between the same regions, each within a chi-square bound on their
// covariances. A false loop from places that look alike is refused however well it registered.
#pragma once

#include "livo/loop/point_types.hpp"

namespace livo::loop {

/// The odometry's drift: the relative pose over a path of L metres has the standard deviations
/// rotation hypot(rotation_floor, rotation_per_m L) and translation hypot(translation_floor,
/// translation_per_m L, rotation_per_m L * L / 2), the last the lever arm of a heading error
/// growing along the path (a constant heading drift b displaces the end by b L^2 / 2 at most).
struct DriftModel {
  double rotation_floor = 2e-4;     // rad
  double translation_floor = 2e-3;  // m
  double rotation_per_m = 2e-4;     // rad per metre
  double translation_per_m = 5e-3;  // m per metre
};

/// Covariance of the right perturbation [rotation; translation] of the odometry's relative pose
/// over `path_m` metres (isotropic blocks).
Mat6 driftCovariance(double path_m, const DriftModel& model);

/// Squared Mahalanobis distance between a measured and a predicted relative pose, both with
/// right-perturbation covariances: e = [Log(R_p^T R_m); R_p^T (t_m - t_p)], e^T (P + M)^-1 e.
double poseChi2(const Pose3& predicted, const Mat6& cov_predicted, const Pose3& measured, const Mat6& cov_measured);

/// The 0.999 quantile of the chi-square distribution with 6 degrees of freedom.
constexpr double kChi2Six999 = 22.458;

}  // namespace livo::loop
