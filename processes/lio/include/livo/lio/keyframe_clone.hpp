// The odometry's relative pose between consecutive keyframes and its covariance, from the filter
// itself (stochastic cloning, Roumeliotis & Burdick 2002). The pose at the last keyframe is kept
// with its covariance, and the cross-covariance of the running state with it is carried by every
// propagation step (with the state's transition: the clone is constant) and every update (with
// I - K H). At the next keyframe the relative pose's covariance follows to first order,
// correlations included: differencing the two absolute covariances cannot give it (with a map
// both barely grow, while the increment between them is as uncertain as the registrations that
// made it). livo-loop weights its odometry edges with it; tests/loop/keyframe_nees.py checks it
// against the simulator's truth.
#pragma once

#include "livo/filter_state.hpp"

namespace livo::lio {

/// Cov(δx, δpose_clone): the filter's error state against the clone's [rotation; position].
using CloneCrossCovariance = Eigen::Matrix<double, FilterState::kDim, 6>;

struct KeyframeClone {
  bool valid = false;
  int64_t keyframe_id = -1;
  Pose3 pose = Pose3::Identity();  // W_T_I at that keyframe
  Mat6 covariance = Mat6::Zero();  // its [rotation (right); position (world)] error covariance
};

/// Covariance of the right perturbation xi = [rotation; translation in b] of T_a^-1 T_b (true
/// relative pose = (R Exp(phi), t + R tau) to first order, livo-loop's convention for its edges),
/// from the filter's errors of the two poses ([rotation, right; position, world] each): their
/// covariances and Cov(δb, δa).
Mat6 relativePoseCovariance(const Pose3& T_a, const Pose3& T_b, const Mat6& P_aa, const Mat6& P_bb,
                            const Mat6& P_ba);

/// A cross-covariance C = Cov(δx, δy) carried through updates of x that took its covariance from
/// P_prior to P_post without touching y: C <- A C with P_post = A P_prior, A = Π (I - K_i H_i),
/// i.e. P_post P_prior^-1 C (exact for Kalman updates and compositions of them). States of zero
/// prior variance (a calibration held fixed) have zero rows in C and are left out of the solve.
CloneCrossCovariance carriedThroughUpdate(const StateCovariance& P_prior, const StateCovariance& P_post,
                                          const CloneCrossCovariance& C);

}  // namespace livo::lio
