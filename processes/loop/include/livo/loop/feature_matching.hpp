// Putative correspondences of the coarse stage: mutual nearest neighbours in FPFH space.
//
// FPFH bins lie in [0, 200], so a feature is stored as 33 bytes (padded to 48) and compared by
// L1 distance, which suits histograms. Matching is exhaustive: every source descriptor against
// every target one, with SSE2 sum-of-absolute-differences (two instructions and one scalar bin per
// pair), finding both directions' nearest neighbours in one pass. In 33 dimensions a kd-tree (nanoflann) visits
// nearly every point anyway: on KITTI keyframes exact kd-tree mutual matching of 2,900 float
// features took 60-85 ms, the byte-wise exhaustive pass over 1,300 keypoints takes about 2 ms.
#pragma once

#include <array>
#include <cstdint>

#include "livo/loop/point_types.hpp"

namespace livo::loop {

/// An FPFH quantised to bytes (bins rounded, saturated at 255), zero-padded to 48 bytes.
struct alignas(16) Descriptor {
  std::array<uint8_t, 48> bins{};
  bool isZero() const;
};
using Descriptors = std::vector<Descriptor>;

Descriptor quantise(const Fpfh& feature);
Descriptors quantise(const Features& features);

/// L1 distance between two descriptors.
int descriptorDistance(const Descriptor& a, const Descriptor& b);

struct FeatureMatchingOptions {
  bool mutual = true;              // keep i <-> j only if each is the other's nearest
  int max_correspondences = 2000;  // keep the best (smallest feature distance) if more
};

/// Nearest neighbours by L1 distance (the lowest index on ties); zero descriptors are skipped.
Correspondences matchDescriptors(const Descriptors& source, const Descriptors& target,
                                 const FeatureMatchingOptions& options = {});

}  // namespace livo::loop
