// Quatro (Lim et al., ICRA 2022): global registration robust to outliers for ground robots.
// From the max-clique inliers it forms translation-invariant measurements (pairwise differences),
// estimates the rotation on the quasi-SO(3) (yaw about gravity only; a full-SO(3) variant is an
// option) with GNC-TLS, then the translation component-wise by adaptive voting (COTE).
#pragma once

#include <cstdint>

#include "livo/loop/feature_matching.hpp"
#include "livo/loop/fpfh.hpp"
#include "livo/loop/max_clique.hpp"
#include "livo/loop/point_types.hpp"

namespace livo::loop {

struct QuatroOptions {
  double noise_bound = 0.3;  // m, the inlier bound of a correspondence
  bool quasi_so3 = true;     // yaw only (clouds in gravity-aligned frames)
  int max_tims = 20000;      // translation-invariant measurements used for the rotation
  double gnc_factor = 1.4;   // GNC: mu *= factor each iteration
  int gnc_max_iterations = 100;
  double gnc_cost_threshold = 1e-6;
  MaxCliqueOptions clique;
};

struct QuatroResult {
  Pose3 T_target_source = Pose3::Identity();
  int num_correspondences = 0;
  int num_clique = 0;   // max-clique size
  int num_inliers = 0;  // clique members consistent with the final transform
  bool clique_exact = true;
  bool valid = false;  // at least 3 inliers and the estimation converged
};

/// Registers matched source/target points (matches index into them).
QuatroResult quatroRegister(const Points& source, const Points& target, const Correspondences& matches,
                            const QuatroOptions& options);

/// Rotation by GNC-TLS on vectors a_i -> b_i (b ≈ R a); `weights` returns the final weights.
Mat3 gncTlsRotation(const Points& a, const Points& b, double noise_bound, bool yaw_only, const QuatroOptions& options,
                    std::vector<double>* weights = nullptr);

/// Scalar TLS by adaptive voting: the estimate maximising the consensus of values within `bound`.
double adaptiveVoting(const std::vector<double>& values, double bound);

}  // namespace livo::loop
