// One loop candidate, coarse to fine (the paper's QN-C2F): Quatro on cached FPFH features, then
// Nano-GICP initialised by it, then acceptance by fitness, overlap, conditioning and the
// agreement of the coarse and fine results. A wrong loop is worse than none.
#pragma once

#include <functional>
#include <string>

#include "livo/loop/coarse_features.hpp"
#include "livo/loop/feature_matching.hpp"
#include "livo/loop/gicp.hpp"
#include "livo/loop/quatro.hpp"

namespace livo::loop {

struct AcceptanceOptions {
  int min_coarse_inliers = 10;  // max-clique inliers consistent with the coarse result (6 let a
                                // 90°-rotated match of a symmetric room through)
  double max_fitness = 0.15;    // m^2, fine mean squared residual
  double min_overlap = 0.5;     // fraction of source points near the target
  double max_coarse_fine_rotation_deg = 5.0;
  double max_coarse_fine_translation = 1.0;  // m
  double min_translation_eigenvalue = 0.05;  // of the per-correspondence GICP Hessian (degeneracy)
  // Smallest / largest eigenvalue of that block. GICP's plane covariances leave every point a
  // weak in-plane term (about 1/2 per point against ~1/(2 epsilon) along the normal), so the
  // absolute bound above never fires in a corridor; the ratio does.
  double min_translation_eigenvalue_ratio = 0.02;  // corridor false loops: 0.003-0.006; KITTI, scan_pair: 0.12-0.64
};

struct LoopRegistrationOptions {
  FeatureMatchingOptions matching;
  QuatroOptions quatro;
  GicpOptions gicp;
  AcceptanceOptions acceptance;
};

struct LoopRegistrationResult {
  QuatroResult coarse;
  GicpResult fine;
  Pose3 T_target_source = Pose3::Identity();
  bool accepted = false;
  std::string reason;       // why it was rejected ("" if accepted)
  std::string rejected_by;  // the test that rejected it, in a few words ("" if accepted)
  double coarse_ms = 0.0;   // matching + clique + rotation + translation (features cached)
  double fine_ms = 0.0;
};

/// Registers `source` onto `target` (both in their own frames).
LoopRegistrationResult registerLoop(const CoarseFeatures& source_coarse, const CoarseFeatures& target_coarse,
                                    const GicpCloud& source_fine, const GicpCloud& target_fine,
                                    const LoopRegistrationOptions& options);

/// The same, with the fine clouds asked for only once the coarse registration has passed (they
/// cost more to build than the coarse step, and most candidates stop there).
LoopRegistrationResult registerLoop(const CoarseFeatures& source_coarse, const CoarseFeatures& target_coarse,
                                    const std::function<const GicpCloud&()>& source_fine,
                                    const std::function<const GicpCloud&()>& target_fine,
                                    const LoopRegistrationOptions& options);

}  // namespace livo::loop
