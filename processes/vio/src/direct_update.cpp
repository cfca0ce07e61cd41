#include "livo/vio/direct_update.hpp"

#include <cmath>
#include <sstream>

#include <Eigen/Cholesky>

#include "livo/esikf_update.hpp"

namespace livo::vio {

namespace {

// Measurement over the active patches at iterate x; returns the number of patches used.
int measure(const std::vector<TrackedPatch>& patches, const std::vector<char>& active, int level,
            const ImagePyramid& pyramid, const CameraProjection& camera, const Pose3& T_I_C, const FilterState& x,
            const PhotometricOptions& o, const RollingShutter& shutter, PoseInformation* info,
            CameraRotationInformation* ci) {
  PatchResidual e;
  int used = 0;
  for (size_t i = 0; i < patches.size(); ++i) {
    if (!active[i] || !evaluatePatch(pyramid, level, camera, T_I_C, x, patches[i], o, &e, shutter)) continue;
    accumulate(e, o, info, ci);
    ++used;
  }
  return used;
}

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(3);
  s << v;
  return s.str();
}

}  // namespace

DirectUpdateResult directUpdate(const FilterState& prior, const Mat18& P_prior, const ImagePyramid& pyramid,
                                const CameraProjection& camera, const Pose3& T_I_C, const PhotometricOptions& po,
                                const UpdateOptions& uo, std::vector<TrackedPatch>* patches_io,
                                const RollingShutter& shutter, const Mat3* cam_cov) {
  std::vector<TrackedPatch>& patches = *patches_io;
  DirectUpdateResult res;
  res.state = prior;
  res.covariance = P_prior;
  FilterState x = prior;
  Mat18 P = P_prior;
  std::vector<char> active(patches.size(), 0);
  PatchResidual e;
  bool stepped_at_finest = false;
  // the camera-rotation correction φ (a nuisance with its own prior N(0, cam_cov), uncorrelated
  // with the filter): eliminated from each step by its Schur complement, then solved for
  Vec3 phi = Vec3::Zero();
  Mat3 cam_info_prior = Mat3::Zero(), A = Mat3::Identity();
  Eigen::Matrix<double, 6, 3> S_xc = Eigen::Matrix<double, 6, 3>::Zero();
  Mat6 S_xx = Mat6::Zero();  // the pose's own information of the last step
  if (cam_cov) cam_info_prior = cam_cov->inverse();
  auto cameraAt = [&](const Vec3& f) { return cam_cov ? T_I_C * se3::fromRotationTranslation(so3::Exp(f), Vec3::Zero()) : T_I_C; };
  for (int level = pyramid.levels() - 1; level >= 0; --level) {
    // the measurement of this level: patches that project (and, once a coarser level has aligned
    // the image, correlate) at the current iterate; at the first level the prior may be off by more
    // than a fine texture's correlation length, so only the robust weights guard it
    const bool gate = res.iterations > 0;
    int n_active = 0;
    for (size_t i = 0; i < patches.size(); ++i) {
      active[i] = evaluatePatch(pyramid, level, camera, cameraAt(phi), x, patches[i], po, &e, shutter) && (!gate || e.ncc >= po.min_ncc);
      n_active += active[i];
    }
    if (n_active < uo.min_patches) {
      if (level > 0) continue;  // a finer level may still have enough
      res.why = "too few patches correlate (" + std::to_string(n_active) + " < " + std::to_string(uo.min_patches) + ")";
      return res;
    }
    for (int it = 0; it < uo.max_iterations; ++it) {
      PoseInformation info;
      CameraRotationInformation ci;
      const int used = measure(patches, active, level, pyramid, camera, cameraAt(phi), x, po, shutter, &info,
                               cam_cov ? &ci : nullptr);
      if (used < uo.min_patches) break;
      Vec18 delta;
      Mat6 S = info.HtRinvH;
      Vec6 g = info.HtRinvz;
      S_xx = S;
      Vec3 r_c = Vec3::Zero();
      if (cam_cov) {
        A = ci.S_cc + cam_info_prior;
        r_c = ci.g_c + cam_info_prior * phi;
        S_xc = ci.S_xc;
        const Eigen::LDLT<Mat3> Ainv(A);
        S -= S_xc * Ainv.solve(S_xc.transpose());
        g -= S_xc * Ainv.solve(r_c);
      }
      informationStep(x, prior, P_prior, S, g, &delta, &P);
      if (!delta.allFinite() || !P.allFinite()) {
        res.why = "update diverged (non-finite step)";
        return res;
      }
      x = x.boxplus(delta);
      if (cam_cov) phi -= A.ldlt().solve(r_c + S_xc.transpose() * delta.head<6>());
      ++res.iterations;
      if (level == 0) {
        stepped_at_finest = true;
        res.num_measurements = info.count;
        res.patches = used;
      }
      if (delta.segment<3>(FilterState::kRot).norm() < uo.convergence_rot &&
          delta.segment<3>(FilterState::kPos).norm() < uo.convergence_pos)
        break;
    }
  }
  if (!stepped_at_finest) {
    res.why = "too few patches project at full resolution";
    return res;
  }

  // photometric quality at the posterior (for map maintenance) and the cost test
  double cost_prior = 0.0, cost_post = 0.0;
  int n_cost = 0;
  for (size_t i = 0; i < patches.size(); ++i) {
    TrackedPatch& t = patches[i];
    t.active = false;
    if (!active[i]) continue;
    PatchResidual ep;
    if (!evaluatePatch(pyramid, 0, camera, T_I_C, prior, t, po, &ep, shutter) ||
        !evaluatePatch(pyramid, 0, camera, cameraAt(phi), x, t, po, &e, shutter))
      continue;
    t.active = true;
    t.ncc = static_cast<float>(e.ncc);
    t.rms = static_cast<float>(std::sqrt(e.r.squaredNorm() / kPatchArea));
    cost_prior += huberCost(ep, po.huber_threshold);
    cost_post += huberCost(e, po.huber_threshold);
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
    res.why = "photometric cost grew (" + fmt(res.cost_prior) + " -> " + fmt(res.cost_post) + ")";
  } else if (!(res.mahalanobis <= uo.max_mahalanobis)) {
    res.why = "step inconsistent with the prior (Mahalanobis^2 " + fmt(res.mahalanobis) + " > " +
              fmt(uo.max_mahalanobis) + ")";
  } else if (step_pos > uo.max_step_pos || step_rot_deg > uo.max_step_rot_deg) {
    res.why = "step too large (" + fmt(step_pos) + " m, " + fmt(step_rot_deg) + " deg)";
  } else {
    res.valid = true;
    res.state = x;
    res.covariance = P;
    if (cam_cov) {
      // φ's posterior: its information less what the pose (under its prior) explains of it
      const Mat6 pose_info = S_xx + P_prior.topLeftCorner<6, 6>().inverse();
      res.camera_rotation = phi;
      res.camera_rotation_cov = (A - S_xc.transpose() * pose_info.ldlt().solve(S_xc)).inverse();
    }
  }
  return res;
}

}  // namespace livo::vio
