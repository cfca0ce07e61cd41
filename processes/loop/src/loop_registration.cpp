#include "livo/loop/loop_registration.hpp"

#include <chrono>
#include <sstream>

namespace livo::loop {

namespace {
double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

LoopRegistrationResult registerLoop(const CoarseFeatures& source_coarse, const CoarseFeatures& target_coarse,
                                    const GicpCloud& source_fine, const GicpCloud& target_fine,
                                    const LoopRegistrationOptions& options) {
  return registerLoop(
      source_coarse, target_coarse, [&]() -> const GicpCloud& { return source_fine; },
      [&]() -> const GicpCloud& { return target_fine; }, options);
}

LoopRegistrationResult registerLoop(const CoarseFeatures& source_coarse, const CoarseFeatures& target_coarse,
                                    const std::function<const GicpCloud&()>& source_fine,
                                    const std::function<const GicpCloud&()>& target_fine,
                                    const LoopRegistrationOptions& options) {
  LoopRegistrationResult r;
  const auto t0 = std::chrono::steady_clock::now();
  const Correspondences matches =
      matchDescriptors(source_coarse.descriptors, target_coarse.descriptors, options.matching);
  r.coarse = quatroRegister(source_coarse.points, target_coarse.points, matches, options.quatro);
  r.coarse_ms = msSince(t0);
  const AcceptanceOptions& a = options.acceptance;
  std::ostringstream why;
  if (!r.coarse.valid || r.coarse.num_inliers < a.min_coarse_inliers) {
    why << "coarse: " << r.coarse.num_inliers << " inliers of " << r.coarse.num_correspondences << " (need "
        << a.min_coarse_inliers << ")";
    r.reason = why.str();
    r.rejected_by = "too few coarse inliers";
    return r;
  }
  const GicpCloud& source = source_fine();
  const GicpCloud& target = target_fine();
  const auto t1 = std::chrono::steady_clock::now();
  r.fine = gicpRegister(source, target, r.coarse.T_target_source, options.gicp);
  r.fine_ms = msSince(t1);
  r.T_target_source = r.fine.T_target_source;
  const Pose3 delta = r.coarse.T_target_source.inverse() * r.fine.T_target_source;
  const double drot = so3::Log(Mat3(delta.linear())).norm() * 180.0 / M_PI;
  const double dtrans = delta.translation().norm();
  if (!r.fine.converged) {
    why << "fine did not converge";
    r.rejected_by = "fine did not converge";
  } else if (r.fine.fitness > a.max_fitness) {
    why << "fitness " << r.fine.fitness << " > " << a.max_fitness;
    r.rejected_by = "fitness";
  } else if (r.fine.overlap < a.min_overlap) {
    why << "overlap " << r.fine.overlap << " < " << a.min_overlap;
    r.rejected_by = "overlap";
  } else if (drot > a.max_coarse_fine_rotation_deg || dtrans > a.max_coarse_fine_translation) {
    why << "coarse and fine disagree by " << drot << " deg, " << dtrans << " m";
    r.rejected_by = "coarse and fine disagree";
  } else if (r.fine.min_translation_eigenvalue < a.min_translation_eigenvalue) {
    why << "degenerate (translation eigenvalue " << r.fine.min_translation_eigenvalue << ")";
    r.rejected_by = "degenerate";
  } else if (r.fine.translation_eigenvalue_ratio < a.min_translation_eigenvalue_ratio) {
    why << "degenerate (translation eigenvalue ratio " << r.fine.translation_eigenvalue_ratio << " < "
        << a.min_translation_eigenvalue_ratio << ")";
    r.rejected_by = "degenerate";
  }
  r.reason = why.str();
  r.accepted = r.reason.empty();
  return r;
}

}  // namespace livo::loop
