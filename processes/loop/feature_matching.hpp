// Putative correspondences of the coarse stage: mutual nearest neighbours in FPFH space.
#pragma once

#include "point_types.hpp"

namespace livo::loop {

struct FeatureMatchingOptions {
  bool mutual = true;               // keep i <-> j only if each is the other's nearest
  int max_correspondences = 2000;   // keep the best (smallest feature distance) if more
};

Correspondences matchFeatures(const Features& source, const Features& target,
                              const FeatureMatchingOptions& options = {});

}  // namespace livo::loop
