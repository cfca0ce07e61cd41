#include "livo/vio/direct_update.hpp"

#include <cmath>

#include <Eigen/Cholesky>

#include "livo/esikf_update.hpp"
#include "livo/text_format.hpp"

namespace livo::vio {

namespace {

// The information of a set of patches at one iterate.
struct Measurement {
  MeasurementInformation info;
  int used = 0;
};

// Adds an evaluated patch to the measurement; returns its Huber cost.
double add(const PatchResidual& e, const PhotometricOptions& o, Measurement* m) {
  ++m->used;
  return accumulate(e, o, &m->info);
}

// Measurement over the active patches at iterate x; `costs` (if given) gets each patch's Huber
// cost, -1 for one not used.
Measurement measure(const std::vector<TrackedPatch>& patches, const std::vector<char>& active, int level,
                    const ImagePyramid& pyramid, const CameraProjection& camera, const FilterState& x,
                    const PhotometricOptions& o, const RollingShutter& shutter, std::vector<double>* costs) {
  Measurement m;
  m.info.calibration_block = FilterState::kCamera;
  PatchResidual e;
  if (costs) costs->assign(patches.size(), -1.0);
  for (size_t i = 0; i < patches.size(); ++i) {
    if (!active[i] || !evaluatePatch(pyramid, level, camera, x, patches[i], o, &e, shutter)) continue;
    const double cost = add(e, o, &m);
    if (costs) (*costs)[i] = cost;
  }
  return m;
}

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
                                std::vector<TrackedPatch>* patches_io, const RollingShutter& shutter) {
  std::vector<TrackedPatch>& patches = *patches_io;
  DirectUpdateResult res;
  res.state = prior;
  res.covariance = P_prior;
  FilterState x = prior;
  StateCovariance P = P_prior;
  std::vector<char> active(patches.size(), 0);
  PatchResidual e;
  bool stepped_at_finest = false;
  const Mat13 P_measured = measuredCovariance(P_prior, FilterState::kCamera);
  Mat13 S_last = Mat13::Zero();  // the information of the last step ...
  FilterState x_lin = prior;     // ... and the iterate it was taken at
  // the image measures the pose only as well as its references' poses were known (reference floor)
  const bool floored = uo.reference_floor > 0.0 && !patches.empty();
  Mat13 floor = Mat13::Zero();
  if (floored) floor.topLeftCorner<6, 6>() = uo.reference_floor * referenceFloor(patches, prior.rot);
  // once the filter knows the gyro bias, the image considers it instead of updating it
  // (UpdateOptions::gyro_bias_std_to_update): a Schmidt step that leaves it at the prior
  const bool consider_gyro_bias =
      std::sqrt(P_prior.block<3, 3>(FilterState::kGyroBias, FilterState::kGyroBias).diagonal().maxCoeff()) <=
      uo.gyro_bias_std_to_update;
  StateVector keep = StateVector::Ones();
  keep.segment<3>(FilterState::kGyroBias).setZero();
  const StateVector* estimated = consider_gyro_bias ? &keep : nullptr;
  // the coarser levels align the pose: the calibration's signal is the parallax of a patch between
  // its views, a fraction of a pixel, which only the full resolution resolves (and a coarse level's
  // step in the time shift would move the references by more than their first-order re-centring
  // covers on a fast vehicle): there the calibration is considered, not updated
  StateVector keep_coarse = estimated ? keep : StateVector::Ones();
  keep_coarse.segment<FilterState::kCalibrationDim>(FilterState::kCamera).setZero();
  // one Gauss-Newton step at `level` from the iterate x (the floor applied if `with_floor`), on
  // `given` (the measurement already taken at this iterate) or measured now
  enum class Step { kStepped, kConverged, kTooFew, kDiverged };
  auto gaussNewtonStep = [&](int level, bool with_floor, const Measurement* given) {
    Measurement measured;
    if (!given) measured = measure(patches, active, level, pyramid, camera, x, po, shutter, nullptr);
    const Measurement& m = given ? *given : measured;
    if (m.used < uo.min_patches) return Step::kTooFew;
    MeasurementInformation info = m.info;
    scaleCalibrationInformation(uo.calibration_information_scale, P_measured, &info);
    if (with_floor) applyMeasurementFloor(floor, &info.HtRinvH, &info.HtRinvz);
    StateVector delta;
    informationStep(x, prior, P_prior, info, &delta, &P, level > 0 ? &keep_coarse : estimated);
    S_last = info.HtRinvH;
    x_lin = x;
    if (!delta.allFinite() || !P.allFinite()) {
      res.why = "update diverged (non-finite step)";
      return Step::kDiverged;
    }
    x = x.boxplus(delta);
    ++res.iterations;
    if (level == 0) {
      stepped_at_finest = true;
      res.num_measurements = info.count;
      res.patches = m.used;
    }
    return delta.segment<3>(FilterState::kRot).norm() < uo.convergence_rot &&
                   delta.segment<3>(FilterState::kPos).norm() < uo.convergence_pos
               ? Step::kConverged
               : Step::kStepped;
  };
  // the alignment: where the photometric residuals put the pose and the calibration
  for (int level = pyramid.levels() - 1; level >= 0; --level) {
    // the measurement of this level: patches that project (and, once a coarser level has aligned
    // the image, correlate) at the current iterate; at the first level the prior may be off by more
    // than a fine texture's correlation length, so only the robust weights guard it
    // (the patches so chosen are the first step's measurement: it is taken at this same iterate)
    const bool gate = res.iterations > 0;
    Measurement first;
    first.info.calibration_block = FilterState::kCamera;
    for (size_t i = 0; i < patches.size(); ++i) {
      active[i] =
          evaluatePatch(pyramid, level, camera, x, patches[i], po, &e, shutter) && (!gate || e.ncc >= po.min_ncc);
      if (active[i]) add(e, po, &first);
    }
    if (first.used < uo.min_patches) {
      if (level > 0) continue;  // a finer level may still have enough
      res.why =
          "too few patches correlate (" + std::to_string(first.used) + " < " + std::to_string(uo.min_patches) + ")";
      return res;
    }
    for (int it = 0; it < uo.max_iterations; ++it) {
      const Step st = gaussNewtonStep(level, false, it == 0 ? &first : nullptr);
      if (st == Step::kTooFew) {
        // the last step took the patches out of where they are measured (off the image, or a
        // reference moved by the calibration's step beyond its first-order re-centring): the
        // iterate it was taken from is the last one measured
        if (it > 0) x = x_lin;
        break;
      }
      if (st == Step::kDiverged) return res;
      if (st == Step::kConverged) break;
    }
  }
  if (!stepped_at_finest) {
    res.why = "too few patches project at full resolution";
    return res;
  }
  // the image's measurement at the aligned state: its consistency with the prior, then (with the
  // reference floor) the fusion, one more step from there with the floored information
  std::vector<double> aligned_cost;  // each patch's Huber cost at the aligned state (-1: not evaluated)
  const Measurement aligned = measure(patches, active, 0, pyramid, camera, x, po, shutter, &aligned_cost);
  if (aligned.used < uo.min_patches) {
    res.why = "too few patches project at the aligned pose (" + std::to_string(aligned.used) + " < " +
              std::to_string(uo.min_patches) + ")";
    return res;
  }
  {
    MeasurementInformation gated = aligned.info;
    scaleCalibrationInformation(uo.calibration_information_scale, P_measured, &gated);
    if (floored) applyMeasurementFloor(floor, &gated.HtRinvH, &gated.HtRinvz);
    res.consistency =
        consistencyTest(measuredDifference(x, prior), gated.HtRinvH, gated.HtRinvz, P_measured, uo.gate_probability);
  }
  // the pose the image aligned to, with the prior's calibration: the cost test's (below)
  FilterState aligned_pose = x;
  aligned_pose.camera = prior.camera;
  if (floored && gaussNewtonStep(0, true, &aligned) == Step::kDiverged) return res;

  // photometric quality at the posterior (for map maintenance) and the cost test: the image must
  // fit better at the pose it aligned to than at the prior (the fusion with the floor may then
  // give some of that back where the prior is surer). The calibration's step is not in it: it is
  // taken with each patch's point and reference pose eliminated (nuisances whose adjustment the
  // raw cost does not make), and its check is the consistency gate.
  double cost_prior = 0.0, cost_post = 0.0;
  int n_cost = 0;
  PatchResidual ep;
  for (size_t i = 0; i < patches.size(); ++i) {
    TrackedPatch& t = patches[i];
    t.active = false;
    if (!active[i] || aligned_cost[i] < 0.0) continue;
    PatchResidual ea;
    if (!evaluatePatch(pyramid, 0, camera, prior, t, po, &ep, shutter) ||
        !evaluatePatch(pyramid, 0, camera, aligned_pose, t, po, &ea, shutter) ||
        !evaluatePatch(pyramid, 0, camera, x, t, po, &e, shutter))
      continue;
    t.active = true;
    t.ncc = static_cast<float>(e.ncc);
    t.rms = static_cast<float>(std::sqrt(e.r.squaredNorm() / kPatchArea));
    cost_prior += huberCost(ep, po.huber_threshold);
    cost_post += huberCost(ea, po.huber_threshold);
    n_cost += kPatchArea;
  }
  if (n_cost > 0) {
    res.cost_prior = cost_prior / n_cost;
    res.cost_post = cost_post / n_cost;
  }
  const StateVector step = x.boxminus(prior);
  const double step_rot_deg = step.segment<3>(FilterState::kRot).norm() * 180.0 / M_PI;
  const double step_pos = step.segment<3>(FilterState::kPos).norm();
  const Vec6 pose_step = step.head<6>();
  const Eigen::LDLT<Mat6> pose_ldlt(P_prior.topLeftCorner<6, 6>());
  const double pose_step_d2 = pose_ldlt.info() == Eigen::Success ? pose_step.dot(pose_ldlt.solve(pose_step)) : INFINITY;
  // (a step within the prior's 1-sigma moves the state less than the prior's own uncertainty: a
  // photometric cost that grows by a few per cent there is the texture's sub-pixel noise, not a
  // failed alignment)
  if (pose_step_d2 > 1.0 && !(res.cost_post <= 1.05 * res.cost_prior + 1e-9)) {
    res.why = "photometric cost grew (" + formatSignificant(res.cost_prior) + " -> " +
              formatSignificant(res.cost_post) + ", pose step " + formatSignificant(std::sqrt(pose_step_d2)) +
              " sigma)";
  } else if (!res.consistency.passed) {
    res.why = "image inconsistent with the prior (chi-square " + formatSignificant(res.consistency.nis) + " > " +
              formatSignificant(res.consistency.threshold) + ", " + std::to_string(res.consistency.dof) + " dof)";
  } else if (step_pos > uo.max_step_pos || step_rot_deg > uo.max_step_rot_deg) {
    res.why = "step too large (" + formatSignificant(step_pos) + " m, " + formatSignificant(step_rot_deg) + " deg)";
  } else {
    res.valid = true;
    res.state = x;
    res.covariance = P;
    if (uo.covariance == CovarianceUpdate::kBeyondPrior) {
      // the covariance counts only the photometric information beyond the prior's (UpdateOptions)
      MeasurementInformation beyond;
      beyond.calibration_block = FilterState::kCamera;
      beyond.HtRinvH = covarianceInformation(S_last, P_measured);
      StateVector unused;
      informationStep(x_lin, prior, P_prior, beyond, &unused, &res.covariance, estimated);
    }
  }
  return res;
}

}  // namespace livo::vio
