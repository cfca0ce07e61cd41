// The iterated ESIKF update (paper eqs. 11-18) in the information form of FAST-LIO:
//   K = (H^T R^-1 H + P^-1)^-1 H^T R^-1,  P = J^-1 P̂ J^-T  (J: the ⊟ Jacobian of eq. 12),
//   x̌ ← x̌ ⊞ (-K z - (I - K H) J^-1 (x̌ ⊟ x̂)),  P̂ ← (I - K H) P,
// for measurements that touch only the pose (the first 6 error states) and one sensor's
// calibration block (its extrinsic and time shift: 7 more), so H^T R^-1 H is a 13x13 block and no
// state-sized matrix is ever inverted:
//   (P^-1 + E S E^T)^-1 = P - P E (I + S P_EE)^-1 S E^T P,  E: the 13 measured states.
// A calibration held fixed (zero prior variance) gets no gain: the update leaves it exactly.
#pragma once

#include <functional>

#include "livo/filter_state.hpp"

namespace livo {

constexpr int kMeasuredDim = 6 + FilterState::kCalibrationDim;
using Mat13 = Eigen::Matrix<double, kMeasuredDim, kMeasuredDim>;
using Vec13 = Eigen::Matrix<double, kMeasuredDim, 1>;

/// Sufficient statistics of a measurement at the current iterate: S = H^T R^-1 H, g = H^T R^-1 z,
/// with the residual z = h(x̌) - measurement and H = ∂z/∂[δr δp δcalibration], the calibration
/// being the block `calibration_block` (FilterState::kLidar or kCamera) of the sensor measured.
struct MeasurementInformation {
  Mat13 HtRinvH = Mat13::Zero();
  Vec13 HtRinvz = Vec13::Zero();
  int calibration_block = FilterState::kLidar;
  int count = 0;                 // scalar residuals
  Mat6 geometry = Mat6::Zero();  // scale-free pose information for the degeneracy test (see Degeneracy)

  Mat6 pose() const { return HtRinvH.topLeftCorner<6, 6>(); }
  /// The error-state index of row/column k of S.
  int stateIndex(int k) const { return k < 6 ? k : calibration_block + (k - 6); }
};

/// Evaluates the measurement at the iterate x (iteration 0 is the prior); false: no usable data.
using Measurement = std::function<bool(const FilterState& x, int iteration, MeasurementInformation* info)>;

struct EsikfOptions {
  int max_iterations = 4;
  double convergence_rot = 1e-4;  // rad: stop when the step is below this ...
  double convergence_pos = 1e-4;  // m: ... and this
};

struct EsikfResult {
  bool valid = false;  // false: no measurement, state and covariance left unchanged
  int iterations = 0;
  bool converged = false;
  MeasurementInformation info;  // of the last iterate
};

/// One information-form step: the Gauss-Newton increment and the updated covariance at iterate x.
/// `estimated` (1 or 0 per error state; null: all 1) makes it a Schmidt "consider" step: the
/// states marked 0 keep their prior value (their gain rows are zero), and the covariance is the
/// Joseph form with that gain, (I - K'H) P (I - K'H)^T + K' R K'^T, which keeps their variance and
/// updates their correlation with the rest. The iterate x must not have moved them from the prior.
void informationStep(const FilterState& x, const FilterState& prior, const StateCovariance& P_prior,
                     const MeasurementInformation& m, StateVector* delta, StateCovariance* P_post,
                     const StateVector* estimated = nullptr);
/// The same for a measurement of the pose alone (information S, gradient g).
void informationStep(const FilterState& x, const FilterState& prior, const StateCovariance& P_prior, const Mat6& S,
                     const Vec6& g, StateVector* delta, StateCovariance* P_post,
                     const StateVector* estimated = nullptr);

/// The measured states' part of P (rows and columns in MeasurementInformation's order).
Mat13 measuredCovariance(const StateCovariance& P, int calibration_block);

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

/// The calibration's share of a measurement's information: S <- S' = D S D with
/// D = diag(1 (pose), sqrt(scale) (calibration)), which scales the calibration's information (the
/// pose eliminated) by `scale`, and g <- S' S⁺ g, which keeps where the measurement on its own puts
/// the measured states (-S⁺ g): a pseudo-measurement at the same optimum, surer of the pose than of
/// the calibration (over the states `P_measured` estimates: those held fixed stay given; nothing
/// changes when no calibration state is estimated). A measurement whose errors repeat from one to the
/// next (the same map points, the same reference patches) says about a constant calibration only
/// a share of what it would if they were independent (UpdateOptions::calibration_information_scale
/// of livo-vio, LioOptions::calibration_information_scale).
void scaleCalibrationInformation(double scale, const Mat13& P_measured, MeasurementInformation* m);

/// informationBeyondPrior over the measured states (S and P in MeasurementInformation's order):
/// the states held fixed (zero prior variance) get nothing.
Mat13 informationBeyondPrior(const Mat13& S, const Mat13& P_measured);

/// applyPoseMeasurementFloor for a measurement of the pose and a calibration block (the floor in
/// MeasurementInformation's order).
void applyMeasurementFloor(const Mat13& floor, Mat13* S, Vec13* g);

/// The consistency of a measurement with the prior (the innovation tested against prior plus
/// measurement covariance). At an iterate x the measurement has information S and gradient g
/// (MeasurementInformation's order) and x ⊟ prior = e over the measured states; the measurement on
/// its own puts them at ν = e - S⁺ g from the prior, which is N(0, P + S⁻¹) when the two agree.
/// In the prior's whitened frame (P = L Lᵀ, W = Lᵀ S L = V diag(λ) Vᵀ) the directions where the
/// measurement says at least `min_information` of what the prior knows (λ >= min_information)
/// give NIS = Σ (vᵢᵀ L⁻¹ ν)² λᵢ / (1 + λᵢ), chi-square with as many degrees of freedom; the test
/// passes below its `probability` quantile. States held fixed (zero prior variance) are left out.
struct ConsistencyTest {
  double nis = 0.0;        // normalised innovation squared
  int dof = 0;             // directions tested
  double threshold = 0.0;  // chi-square quantile for dof (0 when dof is 0)
  bool passed = true;
};
ConsistencyTest consistencyTest(const Vec13& e, const Mat13& S, const Vec13& g, const Mat13& P_measured,
                                double probability, double min_information = 0.01);

/// Iterates from the prior until the step is small or max_iterations; writes the posterior.
EsikfResult iteratedUpdate(const FilterState& prior, const StateCovariance& P_prior, const Measurement& measure,
                           const EsikfOptions& options, FilterState* post, StateCovariance* P_post);

}  // namespace livo
