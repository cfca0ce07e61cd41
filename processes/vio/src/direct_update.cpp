#include "livo/vio/direct_update.hpp"

#include <cmath>

#include <Eigen/Cholesky>

#include "livo/esikf_update.hpp"
#include "livo/text_format.hpp"

namespace livo::vio {

namespace {

// The information of a set of patches at one iterate (with the calibration's, if estimated).
struct Measurement {
  PoseInformation info;
  CalibrationInformation ci;
  int used = 0;
};

// Adds an evaluated patch to the measurement; returns its Huber cost.
double add(const PatchResidual& e, const PhotometricOptions& o, const Vec6& motion, bool with_calibration,
           Measurement* m) {
  ++m->used;
  return with_calibration ? accumulate(e, o, &m->info, motion, &m->ci) : accumulate(e, o, &m->info);
}

// Measurement over the active patches at iterate x; `costs` (if given) gets each patch's Huber
// cost, -1 for one not used.
Measurement measure(const std::vector<TrackedPatch>& patches, const std::vector<char>& active, int level,
                    const ImagePyramid& pyramid, const CameraProjection& camera, const Pose3& T_I_C,
                    const FilterState& x, const PhotometricOptions& o, const RollingShutter& shutter,
                    const Vec6& motion, bool with_calibration, std::vector<double>* costs) {
  Measurement m;
  PatchResidual e;
  if (costs) costs->assign(patches.size(), -1.0);
  for (size_t i = 0; i < patches.size(); ++i) {
    if (!active[i] || !evaluatePatch(pyramid, level, camera, T_I_C, x, patches[i], o, &e, shutter)) continue;
    const double cost = add(e, o, motion, with_calibration, &m);
    if (costs) (*costs)[i] = cost;
  }
  return m;
}

}  // namespace

Mat3 calibrationFloor(const std::vector<TrackedPatch>& patches, const Vec3& c_W, double rotation_std) {
  Mat3 B = Mat3::Zero();
  if (patches.empty()) return B;
  for (const TrackedPatch& t : patches) {
    const Vec3 b = c_W - t.reference_centre;
    B += b.squaredNorm() * Mat3::Identity() - b * b.transpose();  // [b]x [b]x^T
  }
  return rotation_std * rotation_std * B / static_cast<double>(patches.size());
}

Mat6 referenceFloor(const std::vector<TrackedPatch>& patches, const Mat3& R_W_I) {
  Mat6 F = Mat6::Zero();
  if (patches.empty()) return F;
  for (const TrackedPatch& t : patches) F += t.reference_cov_W;
  Mat6 J = Mat6::Identity();
  J.topLeftCorner<3, 3>() = R_W_I.transpose();
  return J * (F / static_cast<double>(patches.size())) * J.transpose();
}

DirectUpdateResult directUpdate(const FilterState& prior, const Mat18& P_prior, const ImagePyramid& pyramid,
                                const CameraProjection& camera, const Pose3& T_I_C, const PhotometricOptions& po,
                                const UpdateOptions& uo, std::vector<TrackedPatch>* patches_io,
                                const RollingShutter& shutter, const CalibrationPrior* calib) {
  std::vector<TrackedPatch>& patches = *patches_io;
  DirectUpdateResult res;
  res.state = prior;
  res.covariance = P_prior;
  FilterState x = prior;
  Mat18 P = P_prior;
  std::vector<char> active(patches.size(), 0);
  PatchResidual e;
  bool stepped_at_finest = false;
  // the calibration correction c: a nuisance with its own prior (CalibrationPrior)
  CalibrationVector c = CalibrationVector::Zero();
  CalibrationMatrix c_info_prior = CalibrationMatrix::Zero(), A = CalibrationMatrix::Identity();
  Eigen::Matrix<double, 6, kCalibrationDim> S_xc = Eigen::Matrix<double, 6, kCalibrationDim>::Zero();
  Mat6 S_xx = Mat6::Zero();  // the pose's own information of the last step
  Mat6 S_last = Mat6::Zero();  // the information of the last step (calibration eliminated) ...
  FilterState x_lin = prior;   // ... and the iterate it was taken at
  Eigen::Matrix<double, kCalibrationDim, 1> free = CalibrationVector::Zero();  // 1: estimated
  if (calib)
    for (int k = 0; k < kCalibrationDim; ++k)
      if (calib->covariance(k, k) > 0.0) free[k] = 1.0;
  if (calib) {
    // the prior information of the free entries (the fixed ones are cut out below)
    CalibrationMatrix cov = calib->covariance;
    for (int k = 0; k < kCalibrationDim; ++k)
      if (free[k] == 0.0) cov.row(k).setZero(), cov.col(k).setZero(), cov(k, k) = 1.0;
    c_info_prior = cov.inverse();
  }
  // the image's position measurement cannot beat what the camera's calibration allows
  // and than what the references' own poses allow
  const bool floored = (uo.calibration_rotation_std_deg > 0.0 || uo.reference_floor > 0.0) && !patches.empty();
  Mat6 pose_floor = Mat6::Zero();
  if (uo.calibration_rotation_std_deg > 0.0)
    pose_floor.bottomRightCorner<3, 3>() = calibrationFloor(patches, (prior.pose() * T_I_C).translation(),
                                                            uo.calibration_rotation_std_deg * M_PI / 180.0);
  if (uo.reference_floor > 0.0) pose_floor += uo.reference_floor * referenceFloor(patches, prior.rot);
  // once the filter knows the gyro bias, the image considers it instead of updating it
  // (UpdateOptions::gyro_bias_std_to_update): a Schmidt step that leaves it at the prior
  const bool consider_gyro_bias =
      std::sqrt(P_prior.block<3, 3>(FilterState::kGyroBias, FilterState::kGyroBias).diagonal().maxCoeff()) <=
      uo.gyro_bias_std_to_update;
  Vec18 keep = Vec18::Ones();
  keep.segment<3>(FilterState::kGyroBias).setZero();
  const Vec18* estimated = consider_gyro_bias ? &keep : nullptr;
  auto cameraAt = [&](const CalibrationVector& f) {
    return calib ? T_I_C * se3::fromRotationTranslation(so3::Exp(f.head<3>()), f.segment<3>(3)) : T_I_C;
  };
  // the state at the image's true time (stamp + δt)
  auto stateAt = [&](const FilterState& xi, const CalibrationVector& f) {
    return calib ? advanced(xi, calib->omega_I, calib->time_offset + f[6]) : xi;
  };
  // d pixel / d δt needs the body's motion at the iterate
  auto motionAt = [&](const FilterState& xs) {
    Vec6 motion = Vec6::Zero();
    if (calib) motion << calib->omega_I, xs.vel;
    return motion;
  };
  // one Gauss-Newton step at `level` from the iterate x (the floors applied if `with_floor`), on
  // `given` (the measurement already taken at this iterate) or measured now (each patch's cost into
  // `costs`, if given)
  enum class Step { kStepped, kConverged, kTooFew, kDiverged };
  auto gaussNewtonStep = [&](int level, bool with_floor, const Measurement* given, std::vector<double>* costs) {
    Measurement measured;
    if (!given) {
      const FilterState xs = stateAt(x, c);
      measured = measure(patches, active, level, pyramid, camera, cameraAt(c), xs, po, shutter, motionAt(xs),
                         calib != nullptr, costs);
    }
    const Measurement& m = given ? *given : measured;
    const PoseInformation& info = m.info;
    const CalibrationInformation& ci = m.ci;
    const int used = m.used;
    if (used < uo.min_patches) return Step::kTooFew;
    Vec18 delta;
    Mat6 S = info.HtRinvH;
    Vec6 g = info.HtRinvz;
    S_xx = S;
    CalibrationVector r_c = CalibrationVector::Zero();
    if (calib) {
      const CalibrationMatrix mask = free.asDiagonal();
      A = mask * (ci.S_cc + c_info_prior) * mask + (CalibrationMatrix::Identity() - mask);
      r_c = mask * (ci.g_c + c_info_prior * c);
      S_xc = ci.S_xc * mask;
      const Eigen::LDLT<CalibrationMatrix> Ainv(A);
      S -= S_xc * Ainv.solve(S_xc.transpose());
      g -= S_xc * Ainv.solve(r_c);
    }
    if (with_floor) applyPoseMeasurementFloor(pose_floor, &S, &g);
    informationStep(x, prior, P_prior, S, g, &delta, &P, estimated);
    S_last = S;
    x_lin = x;
    if (!delta.allFinite() || !P.allFinite()) {
      res.why = "update diverged (non-finite step)";
      return Step::kDiverged;
    }
    x = x.boxplus(delta);
    if (calib) c -= A.ldlt().solve(r_c + S_xc.transpose() * delta.head<6>());
    ++res.iterations;
    if (level == 0) {
      stepped_at_finest = true;
      res.num_measurements = info.count;
      res.patches = used;
    }
    return delta.segment<3>(FilterState::kRot).norm() < uo.convergence_rot &&
                   delta.segment<3>(FilterState::kPos).norm() < uo.convergence_pos
               ? Step::kConverged
               : Step::kStepped;
  };
  for (int level = pyramid.levels() - 1; level >= 0; --level) {
    // the measurement of this level: patches that project (and, once a coarser level has aligned
    // the image, correlate) at the current iterate; at the first level the prior may be off by more
    // than a fine texture's correlation length, so only the robust weights guard it
    // (the patches so chosen are the first step's measurement: it is taken at this same iterate)
    const bool gate = res.iterations > 0;
    const Pose3 T_I_C_level = cameraAt(c);
    const FilterState x_level = stateAt(x, c);
    const Vec6 motion = motionAt(x_level);
    Measurement first;
    for (size_t i = 0; i < patches.size(); ++i) {
      active[i] = evaluatePatch(pyramid, level, camera, T_I_C_level, x_level, patches[i], po, &e, shutter) &&
                  (!gate || e.ncc >= po.min_ncc);
      if (active[i]) add(e, po, motion, calib != nullptr, &first);
    }
    const int n_active = first.used;
    if (n_active < uo.min_patches) {
      if (level > 0) continue;  // a finer level may still have enough
      res.why = "too few patches correlate (" + std::to_string(n_active) + " < " + std::to_string(uo.min_patches) + ")";
      return res;
    }
    for (int it = 0; it < uo.max_iterations; ++it) {
      const Step st = gaussNewtonStep(level, false, it == 0 ? &first : nullptr, nullptr);
      if (st == Step::kTooFew) break;
      if (st == Step::kDiverged) return res;
      if (st == Step::kConverged) break;
    }
  }
  if (!stepped_at_finest) {
    res.why = "too few patches project at full resolution";
    return res;
  }
  // the floors: the alignment above found where the image puts the pose; its measurement of the
  // pose, though, is only as good as the calibration and the references' poses allow, so the
  // fusion with the prior is one more step from there with the floored information
  std::vector<double> aligned_cost;  // each patch's Huber cost at the aligned pose (-1: not evaluated)
  if (floored) {
    const Step st = gaussNewtonStep(0, true, nullptr, &aligned_cost);
    if (st == Step::kDiverged) return res;
    if (st == Step::kTooFew) {
      res.why = "too few patches project at the aligned pose";
      return res;
    }
  }


  // photometric quality at the posterior (for map maintenance) and the cost test: the image must
  // fit better at the pose it aligned to than at the prior (the fusion with floors may then give
  // some of that back where the prior is surer)
  double cost_prior = 0.0, cost_post = 0.0;
  int n_cost = 0;
  // (at the aligned pose the floored step measured them: its costs are those)
  PatchResidual ep;
  const FilterState prior_at_image = stateAt(prior, CalibrationVector::Zero());
  const Pose3 T_I_C_post = cameraAt(c);
  const FilterState x_post = stateAt(x, c);
  for (size_t i = 0; i < patches.size(); ++i) {
    TrackedPatch& t = patches[i];
    t.active = false;
    if (!active[i]) continue;
    if (!evaluatePatch(pyramid, 0, camera, T_I_C, prior_at_image, t, po, &ep, shutter) ||
        !evaluatePatch(pyramid, 0, camera, T_I_C_post, x_post, t, po, &e, shutter) || (floored && aligned_cost[i] < 0.0))
      continue;
    t.active = true;
    t.ncc = static_cast<float>(e.ncc);
    t.rms = static_cast<float>(std::sqrt(e.r.squaredNorm() / kPatchArea));
    cost_prior += huberCost(ep, po.huber_threshold);
    cost_post += floored ? aligned_cost[i] : huberCost(e, po.huber_threshold);
    n_cost += kPatchArea;
  }
  if (n_cost > 0) {
    res.cost_prior = cost_prior / n_cost;
    res.cost_post = cost_post / n_cost;
  }
  const Vec18 step = x.boxminus(prior);
  const Vec6 dpose = step.head<6>();
  const Eigen::LDLT<Mat6> ldlt(P_prior.topLeftCorner<6, 6>());
  res.mahalanobis = ldlt.info() == Eigen::Success ? dpose.dot(ldlt.solve(dpose)) : INFINITY;
  const double step_rot_deg = dpose.head<3>().norm() * 180.0 / M_PI, step_pos = dpose.tail<3>().norm();
  if (!(res.cost_post <= 1.05 * res.cost_prior + 1e-9)) {
    res.why = "photometric cost grew (" + formatSignificant(res.cost_prior) + " -> " + formatSignificant(res.cost_post) + ")";
  } else if (!(res.mahalanobis <= uo.max_mahalanobis)) {
    res.why = "step inconsistent with the prior (Mahalanobis^2 " + formatSignificant(res.mahalanobis) + " > " +
              formatSignificant(uo.max_mahalanobis) + ")";
  } else if (step_pos > uo.max_step_pos || step_rot_deg > uo.max_step_rot_deg) {
    res.why = "step too large (" + formatSignificant(step_pos) + " m, " + formatSignificant(step_rot_deg) + " deg)";
  } else {
    res.valid = true;
    res.state = x;
    res.covariance = P;
    if (uo.covariance == CovarianceUpdate::kBeyondPrior) {
      // the covariance counts only the photometric information beyond the prior's (UpdateOptions)
      Vec18 unused;
      informationStep(x_lin, prior, P_prior, informationBeyondPrior(S_last, P_prior.topLeftCorner<6, 6>()),
                      Vec6::Zero(), &unused, &res.covariance, estimated);
    }
    if (calib) {
      // c's posterior: its information less what the pose (under its prior) explains of it; the
      // fixed entries keep a zero variance
      const Mat6 pose_info = S_xx + P_prior.topLeftCorner<6, 6>().inverse();
      const CalibrationMatrix mask = free.asDiagonal();
      res.calibration = c;
      res.calibration_cov = mask * (A - S_xc.transpose() * pose_info.ldlt().solve(S_xc)).inverse() * mask;
    }
  }
  return res;
}

}  // namespace livo::vio
