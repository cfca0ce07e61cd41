// The iterated ESIKF update (paper eqs. 11-18) in the information form of FAST-LIO:
//   K = (H^T R^-1 H + P^-1)^-1 H^T R^-1,  P = J^-1 P̂ J^-T  (J: the ⊟ Jacobian of eq. 12),
//   x̌ ← x̌ ⊞ (-K z - (I - K H) J^-1 (x̌ ⊟ x̂)),  P̂ ← (I - K H) P,
// for measurements that touch only the pose (the first 6 error states), so H^T R^-1 H is a 6x6
// block and no 18x18 matrix is ever inverted:
//   (P^-1 + E S E^T)^-1 = P - P E (I + S P_66)^-1 S E^T P,  E = [I_6; 0].
#pragma once

#include <functional>

#include "livo/filter_state.hpp"

namespace livo {

/// Sufficient statistics of a pose measurement at the current iterate: S = H^T R^-1 H (6x6),
/// g = H^T R^-1 z (6), with the residual z = h(x̌) - measurement and H = ∂z/∂[δr δp].
struct PoseInformation {
  Mat6 HtRinvH = Mat6::Zero();
  Vec6 HtRinvz = Vec6::Zero();
  int count = 0;               // scalar residuals
  Mat6 geometry = Mat6::Zero();// scale-free information for the degeneracy test (see Degeneracy)
};

/// Evaluates the measurement at the iterate x (iteration 0 is the prior); false: no usable data.
using PoseMeasurement = std::function<bool(const FilterState& x, int iteration, PoseInformation* info)>;

struct EsikfOptions {
  int max_iterations = 4;
  double convergence_rot = 1e-4;  // rad: stop when the step is below this ...
  double convergence_pos = 1e-4;  // m: ... and this
};

struct EsikfResult {
  bool valid = false;  // false: no measurement, state and covariance left unchanged
  int iterations = 0;
  bool converged = false;
  PoseInformation info;  // of the last iterate
};

/// One information-form step: the Gauss-Newton increment and the updated covariance at iterate x.
/// `estimated` (1 or 0 per error state; null: all 1) makes it a Schmidt "consider" step: the
/// states marked 0 keep their prior value (their gain rows are zero), and the covariance is the
/// Joseph form with that gain, (I - K'H) P (I - K'H)^T + K' R K'^T, which keeps their variance and
/// updates their correlation with the rest. The iterate x must not have moved them from the prior.
void informationStep(const FilterState& x, const FilterState& prior, const Mat18& P_prior, const Mat6& S,
                     const Vec6& g, Vec18* delta, Mat18* P_post, const Vec18* estimated = nullptr);

/// The part of a pose measurement's information S that exceeds the prior's, direction by
/// direction: with P_pose = L L^T and L^T S L = V diag(λ) V^T (the measurement's information in
/// units of the prior's), L^-T V diag(max(0, λ - 1)) V^T L^-1. A posterior that adds only this has
/// the pose information max(prior, measurement) in every direction: the ellipsoidal intersection
/// (Sijs & Lazar, 2012) of two estimates whose correlation is unknown.
Mat6 informationBeyondPrior(const Mat6& S, const Mat6& P_pose);

/// A pose measurement (information S, gradient g at the iterate) whose error has, besides the
/// noise S models, a part of covariance `floor` that more data does not average away (a
/// calibration bias, a map error): the measurement of covariance S^-1 + floor, i.e.
/// S <- (I + S floor)^-1 S and g <- (I + S floor)^-1 g. The measurement's own minimiser
/// (S^-1 g) is unchanged; S may be singular (no information stays no information).
void applyPoseMeasurementFloor(const Mat6& floor, Mat6* S, Vec6* g);

/// Iterates from the prior until the step is small or max_iterations; writes the posterior.
EsikfResult iteratedUpdate(const FilterState& prior, const Mat18& P_prior, const PoseMeasurement& measure,
                           const EsikfOptions& options, FilterState* post, Mat18* P_post);

}  // namespace livo
