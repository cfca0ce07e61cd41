#include "livo/vio/direct_update.hpp"

#include <cmath>

#include <Eigen/Cholesky>

#include "livo/esikf_update.hpp"
#include "livo/text_format.hpp"

namespace livo::vio {

namespace {

constexpr const char* kDiverged = "update diverged (non-finite step)";

// The information an update's covariance counts with UpdateOptions::kBeyondPrior: the pose's beyond
// the prior's (informationBeyondPrior: the patches are the filter's own past estimates), and the
// calibration's with the pose eliminated (its Schur complement), as an independent block.
Mat13 covarianceInformation(const Mat13& S, const Mat13& P_measured) {
  Mat13 out = Mat13::Zero();
  const Mat6 Spp = S.topLeftCorner<6, 6>();
  out.topLeftCorner<6, 6>() = informationBeyondPrior(Spp, P_measured.topLeftCorner<6, 6>());
  constexpr int c = FilterState::kCalibrationDim;
  const Eigen::Matrix<double, 6, c> Spc = S.topRightCorner<6, c>();
  const Eigen::LDLT<Mat6> ldlt(Spp);
  Eigen::Matrix<double, c, c> Sc = S.bottomRightCorner<c, c>();
  if (ldlt.info() == Eigen::Success) Sc -= Spc.transpose() * ldlt.solve(Spc);
  out.bottomRightCorner<c, c>() = 0.5 * (Sc + Sc.transpose());
  return out;
}

// The measured states' part of x ⊟ prior (MeasurementInformation's order, the camera's block).
Vec13 measuredDifference(const FilterState& x, const FilterState& prior) {
  const StateVector d = x.boxminus(prior);
  Vec13 e;
  e << d.head<6>(), d.segment<FilterState::kCalibrationDim>(FilterState::kCamera);
  return e;
}

// The information of a set of patches at one iterate.
struct Measurement {
  MeasurementInformation info;
  int used = 0;
};

// The image a patch is evaluated in, and how: the pyramid, the camera, the photometric options and
// the shutter.
struct Photometry {
  const ImagePyramid& pyramid;
  const CameraProjection& camera;
  const PhotometricOptions& options;
  const RollingShutter& shutter;

  bool evaluate(int level, const FilterState& x, const TrackedPatch& patch, PatchResidual* e) const {
    return evaluatePatch(pyramid, level, camera, x, patch, options, e, shutter);
  }
};

// What the update holds fixed: the prior, its measured block, the reference floor and the states
// each step updates.
struct UpdateProblem {
  UpdateProblem(const FilterState& prior, const StateCovariance& P_prior, const std::vector<TrackedPatch>& patches,
                const UpdateOptions& uo);

  /// The states a step updates (1) or considers (0); nullptr: all updated.
  const StateVector* estimated() const { return consider_gyro_bias ? &keep : nullptr; }
  /// ... at `level`.
  const StateVector* estimatedAt(int level) const { return level > 0 ? &keep_coarse : estimated(); }

  const FilterState& prior;
  const StateCovariance& P_prior;
  Mat13 P_measured;
  bool floored = false;
  Mat13 floor = Mat13::Zero();
  bool consider_gyro_bias = false;
  StateVector keep;         // the gyro bias considered
  StateVector keep_coarse;  // the coarser levels': the calibration considered too
};

UpdateProblem::UpdateProblem(const FilterState& prior_in, const StateCovariance& P_prior_in,
                             const std::vector<TrackedPatch>& patches, const UpdateOptions& uo)
    : prior(prior_in), P_prior(P_prior_in), P_measured(measuredCovariance(P_prior_in, FilterState::kCamera)) {
  // the image measures the pose only as well as its references' poses were known (reference floor)
  floored = uo.reference_floor > 0.0 && !patches.empty();
  if (floored) floor.topLeftCorner<6, 6>() = uo.reference_floor * referenceFloor(patches, prior.rot);
  // once the filter knows the gyro bias, the image considers it instead of updating it
  // (UpdateOptions::gyro_bias_std_to_update): a Schmidt step that leaves it at the prior
  consider_gyro_bias =
      std::sqrt(P_prior.block<3, 3>(FilterState::kGyroBias, FilterState::kGyroBias).diagonal().maxCoeff()) <=
      uo.gyro_bias_std_to_update;
  keep = StateVector::Ones();
  keep.segment<3>(FilterState::kGyroBias).setZero();
  // the coarser levels align the pose: the calibration's signal is the parallax of a patch between
  // its views, a fraction of a pixel, which only the full resolution resolves (and a coarse level's
  // step in the time shift would move the references by more than their first-order re-centring
  // covers on a fast vehicle): there the calibration is considered, not updated
  keep_coarse = consider_gyro_bias ? keep : StateVector::Ones();
  keep_coarse.segment<FilterState::kCalibrationDim>(FilterState::kCamera).setZero();
}

// Where the Gauss-Newton iteration is, and what it has done.
struct Iterate {
  Iterate(const FilterState& prior, const StateCovariance& P_prior) : x(prior), P(P_prior), x_lin(prior) {}

  FilterState x;
  StateCovariance P;
  Mat13 S_last = Mat13::Zero();  // the information of the last step ...
  FilterState x_lin;             // ... and the iterate it was taken at
  int steps = 0;
  bool stepped_at_finest = false;
  int num_measurements = 0;  // of the last full-resolution step
  int patches = 0;
};

// Adds an evaluated patch to the measurement; returns its Huber cost.
double add(const PatchResidual& e, const PhotometricOptions& o, Measurement* m) {
  ++m->used;
  return accumulate(e, o, &m->info);
}

// Measurement over the active patches at iterate x; `costs` (if given) gets each patch's Huber
// cost, -1 for one not used.
Measurement measure(const Photometry& ph, const std::vector<TrackedPatch>& patches, const std::vector<char>& active,
                    int level, const FilterState& x, std::vector<double>* costs) {
  Measurement m;
  m.info.calibration_block = FilterState::kCamera;
  PatchResidual e;
  if (costs) costs->assign(patches.size(), -1.0);
  for (size_t i = 0; i < patches.size(); ++i) {
    if (!active[i] || !ph.evaluate(level, x, patches[i], &e)) continue;
    const double cost = add(e, ph.options, &m);
    if (costs) (*costs)[i] = cost;
  }
  return m;
}

// The measurement a level starts from: the patches that project (and, with `gate`, once a coarser
// level has aligned the image, correlate) at the iterate x, marked in `active`.
Measurement measureLevel(const Photometry& ph, const std::vector<TrackedPatch>& patches, int level,
                         const FilterState& x, bool gate, std::vector<char>* active) {
  Measurement first;
  first.info.calibration_block = FilterState::kCamera;
  PatchResidual e;
  for (size_t i = 0; i < patches.size(); ++i) {
    (*active)[i] = ph.evaluate(level, x, patches[i], &e) && (!gate || e.ncc >= ph.options.min_ncc);
    if ((*active)[i]) add(e, ph.options, &first);
  }
  return first;
}

enum class Step { kStepped, kConverged, kTooFew, kDiverged };

// One Gauss-Newton step at `level` from the iterate, on the measurement m taken there (the floor
// applied if `with_floor`).
Step gaussNewtonStep(const UpdateProblem& pb, const Measurement& m, int level, bool with_floor, const UpdateOptions& uo,
                     Iterate* it) {
  if (m.used < uo.min_patches) return Step::kTooFew;
  MeasurementInformation info = m.info;
  scaleCalibrationInformation(uo.calibration_information_scale, pb.P_measured, &info);
  if (with_floor) applyMeasurementFloor(pb.floor, &info.HtRinvH, &info.HtRinvz);
  StateVector delta;
  informationStep(it->x, pb.prior, pb.P_prior, info, &delta, &it->P, pb.estimatedAt(level));
  it->S_last = info.HtRinvH;
  it->x_lin = it->x;
  if (!delta.allFinite() || !it->P.allFinite()) return Step::kDiverged;
  it->x = it->x.boxplus(delta);
  ++it->steps;
  if (level == 0) {
    it->stepped_at_finest = true;
    it->num_measurements = info.count;
    it->patches = m.used;
  }
  return delta.segment<3>(FilterState::kRot).norm() < uo.convergence_rot &&
                 delta.segment<3>(FilterState::kPos).norm() < uo.convergence_pos
             ? Step::kConverged
             : Step::kStepped;
}

// Gauss-Newton steps at one level, the first on `first` (taken at the iterate the level starts
// from), until converged or out of iterations; false if a step diverged.
bool iterateLevel(const UpdateProblem& pb, const Photometry& ph, const std::vector<TrackedPatch>& patches,
                  const std::vector<char>& active, int level, const Measurement& first, const UpdateOptions& uo,
                  Iterate* it) {
  for (int i = 0; i < uo.max_iterations; ++i) {
    const Step st =
        i == 0 ? gaussNewtonStep(pb, first, level, false, uo, it)
               : gaussNewtonStep(pb, measure(ph, patches, active, level, it->x, nullptr), level, false, uo, it);
    if (st == Step::kTooFew) {
      // the last step took the patches out of where they are measured (off the image, or a
      // reference moved by the calibration's step beyond its first-order re-centring): the
      // iterate it was taken from is the last one measured
      if (i > 0) it->x = it->x_lin;
      return true;
    }
    if (st == Step::kDiverged) return false;
    if (st == Step::kConverged) return true;
  }
  return true;
}

// The alignment, coarse to fine: where the photometric residuals put the pose and the calibration.
// Returns why it failed ("" when aligned at full resolution).
std::string align(const UpdateProblem& pb, const Photometry& ph, const std::vector<TrackedPatch>& patches,
                  const UpdateOptions& uo, std::vector<char>* active, Iterate* it) {
  for (int level = ph.pyramid.levels() - 1; level >= 0; --level) {
    // the measurement of this level: patches that project (and, once a coarser level has aligned
    // the image, correlate) at the current iterate; at the first level the prior may be off by more
    // than a fine texture's correlation length, so only the robust weights guard it
    // (the patches so chosen are the first step's measurement: it is taken at this same iterate)
    const Measurement first = measureLevel(ph, patches, level, it->x, it->steps > 0, active);
    if (first.used < uo.min_patches) {
      if (level > 0) continue;  // a finer level may still have enough
      return "too few patches correlate (" + std::to_string(first.used) + " < " + std::to_string(uo.min_patches) + ")";
    }
    if (!iterateLevel(pb, ph, patches, *active, level, first, uo, it)) return kDiverged;
  }
  if (!it->stepped_at_finest) return "too few patches project at full resolution";
  return "";
}

// The image's measurement (with the reference floor) tested against the prior at the aligned x.
ConsistencyTest consistencyWithPrior(const UpdateProblem& pb, const Measurement& aligned, const FilterState& x,
                                     const UpdateOptions& uo) {
  MeasurementInformation gated = aligned.info;
  scaleCalibrationInformation(uo.calibration_information_scale, pb.P_measured, &gated);
  if (pb.floored) applyMeasurementFloor(pb.floor, &gated.HtRinvH, &gated.HtRinvz);
  return consistencyTest(measuredDifference(x, pb.prior), gated.HtRinvH, gated.HtRinvz, pb.P_measured,
                         uo.gate_probability);
}

struct PhotometricCost {
  double prior = 0.0, post = 0.0;  // Huber cost per residual
};

// Photometric quality at the posterior x (each patch's active / ncc / rms, for map maintenance) and
// the cost at the prior and at the pose the image aligned to, over the patches evaluated at all
// three (`aligned_cost` >= 0: evaluated at the aligned state).
PhotometricCost posteriorCost(const Photometry& ph, const FilterState& prior, const FilterState& aligned_pose,
                              const FilterState& x, const std::vector<char>& active,
                              const std::vector<double>& aligned_cost, std::vector<TrackedPatch>* patches) {
  double cost_prior = 0.0, cost_post = 0.0;
  int n_cost = 0;
  PatchResidual ep, e;
  for (size_t i = 0; i < patches->size(); ++i) {
    TrackedPatch& t = (*patches)[i];
    t.active = false;
    if (!active[i] || aligned_cost[i] < 0.0) continue;
    PatchResidual ea;
    if (!ph.evaluate(0, prior, t, &ep) || !ph.evaluate(0, aligned_pose, t, &ea) || !ph.evaluate(0, x, t, &e)) continue;
    t.active = true;
    t.ncc = static_cast<float>(e.ncc);
    t.rms = static_cast<float>(std::sqrt(e.r.squaredNorm() / kPatchArea));
    cost_prior += huberCost(ep, ph.options.huber_threshold);
    cost_post += huberCost(ea, ph.options.huber_threshold);
    n_cost += kPatchArea;
  }
  PhotometricCost cost;
  if (n_cost > 0) {
    cost.prior = cost_prior / n_cost;
    cost.post = cost_post / n_cost;
  }
  return cost;
}

// Why the update from the prior to x is not adopted ("" when it is): the photometric cost, the
// consistency gate, the step bounds.
std::string refusal(const FilterState& prior, const StateCovariance& P_prior, const FilterState& x,
                    const DirectUpdateResult& res, const UpdateOptions& uo) {
  const StateVector step = x.boxminus(prior);
  const double step_rot_deg = step.segment<3>(FilterState::kRot).norm() * 180.0 / M_PI;
  const double step_pos = step.segment<3>(FilterState::kPos).norm();
  const Vec6 pose_step = step.head<6>();
  const Eigen::LDLT<Mat6> pose_ldlt(P_prior.topLeftCorner<6, 6>());
  const double pose_step_d2 = pose_ldlt.info() == Eigen::Success ? pose_step.dot(pose_ldlt.solve(pose_step)) : INFINITY;
  // (a step within the prior's 1-sigma moves the state less than the prior's own uncertainty: a
  // photometric cost that grows by a few per cent there is the texture's sub-pixel noise, not a
  // failed alignment)
  if (pose_step_d2 > 1.0 && !(res.cost_post <= 1.05 * res.cost_prior + 1e-9))
    return "photometric cost grew (" + formatSignificant(res.cost_prior) + " -> " + formatSignificant(res.cost_post) +
           ", pose step " + formatSignificant(std::sqrt(pose_step_d2)) + " sigma)";
  if (!res.consistency.passed)
    return "image inconsistent with the prior (chi-square " + formatSignificant(res.consistency.nis) + " > " +
           formatSignificant(res.consistency.threshold) + ", " + std::to_string(res.consistency.dof) + " dof)";
  if (step_pos > uo.max_step_pos || step_rot_deg > uo.max_step_rot_deg)
    return "step too large (" + formatSignificant(step_pos) + " m, " + formatSignificant(step_rot_deg) + " deg)";
  return "";
}

// The posterior covariance (UpdateOptions::covariance): the last step's, or with kBeyondPrior one
// that counts only the photometric information beyond the prior's.
StateCovariance posteriorCovariance(const UpdateProblem& pb, const Iterate& it, const UpdateOptions& uo) {
  StateCovariance P = it.P;
  if (uo.covariance == CovarianceUpdate::kBeyondPrior) {
    MeasurementInformation beyond;
    beyond.calibration_block = FilterState::kCamera;
    beyond.HtRinvH = covarianceInformation(it.S_last, pb.P_measured);
    StateVector unused;
    informationStep(it.x_lin, pb.prior, pb.P_prior, beyond, &unused, &P, pb.estimated());
  }
  return P;
}

// After the alignment: the image's measurement at the aligned state, its consistency with the
// prior, then (with the reference floor) the fusion, one more step from there with the floored
// information; then the cost test and the verdict (into `res`). Returns why the update is not
// adopted ("" when it is).
std::string testAndFuse(const UpdateProblem& pb, const Photometry& ph, const UpdateOptions& uo,
                        const std::vector<char>& active, std::vector<TrackedPatch>* patches, Iterate* it,
                        DirectUpdateResult* res) {
  std::vector<double> aligned_cost;  // each patch's Huber cost at the aligned state (-1: not evaluated)
  const Measurement aligned = measure(ph, *patches, active, 0, it->x, &aligned_cost);
  if (aligned.used < uo.min_patches)
    return "too few patches project at the aligned pose (" + std::to_string(aligned.used) + " < " +
           std::to_string(uo.min_patches) + ")";
  res->consistency = consistencyWithPrior(pb, aligned, it->x, uo);
  // the pose the image aligned to, with the prior's calibration: the cost test's (below)
  FilterState aligned_pose = it->x;
  aligned_pose.camera = pb.prior.camera;
  if (pb.floored && gaussNewtonStep(pb, aligned, 0, true, uo, it) == Step::kDiverged) return kDiverged;
  // the cost test: the image must fit better at the pose it aligned to than at the prior (the
  // fusion with the floor may then give some of that back where the prior is surer). The
  // calibration's step is not in it: it is taken with each patch's point and reference pose
  // eliminated (nuisances whose adjustment the raw cost does not make), and its check is the
  // consistency gate.
  const PhotometricCost cost = posteriorCost(ph, pb.prior, aligned_pose, it->x, active, aligned_cost, patches);
  res->cost_prior = cost.prior;
  res->cost_post = cost.post;
  std::string why = refusal(pb.prior, pb.P_prior, it->x, *res, uo);
  if (!why.empty()) return why;
  res->valid = true;
  res->state = it->x;
  res->covariance = posteriorCovariance(pb, *it, uo);
  return "";
}

}  // namespace

Mat6 referenceFloor(const std::vector<TrackedPatch>& patches, const Mat3& R_W_I) {
  Mat6 F = Mat6::Zero();
  if (patches.empty()) return F;
  for (const TrackedPatch& t : patches) F += t.reference_cov_W;
  Mat6 J = Mat6::Identity();
  J.topLeftCorner<3, 3>() = R_W_I.transpose();
  return J * (F / static_cast<double>(patches.size())) * J.transpose();
}

DirectUpdateResult directUpdate(const FilterState& prior, const StateCovariance& P_prior, const ImagePyramid& pyramid,
                                const CameraProjection& camera, const PhotometricOptions& po, const UpdateOptions& uo,
                                std::vector<TrackedPatch>* patches, const RollingShutter& shutter) {
  const UpdateProblem problem(prior, P_prior, *patches, uo);
  const Photometry ph{pyramid, camera, po, shutter};
  Iterate it(prior, P_prior);
  DirectUpdateResult res;
  res.state = prior;
  res.covariance = P_prior;
  std::vector<char> active(patches->size(), 0);
  res.why = align(problem, ph, *patches, uo, &active, &it);
  if (res.why.empty()) res.why = testAndFuse(problem, ph, uo, active, patches, &it, &res);
  res.iterations = it.steps;
  res.num_measurements = it.num_measurements;
  res.patches = it.patches;
  return res;
}

}  // namespace livo::vio
