// Least-squares similarity between two point sets (Umeyama, IEEE PAMI 1991), with or without
// scale, as evo's `geometry.umeyama_alignment` computes it.
#pragma once

#include <stdexcept>
#include <vector>

#include "livo/so3.hpp"

namespace livo::evaluate {

class AlignmentError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// x -> scale * rotation * x + translation.
struct Similarity3 {
  Mat3 rotation = Mat3::Identity();
  Vec3 translation = Vec3::Zero();
  double scale = 1.0;

  Vec3 apply(const Vec3& x) const { return rotation * (scale * x) + translation; }
  /// A body pose moved by the similarity: rotation R * R_i, position apply(t_i) (evo scales the
  /// path's translations, then left-multiplies the SE(3) part).
  Pose3 apply(const Pose3& T) const;
  Eigen::Matrix4d matrix() const;
};

/// The centroids of two point sets paired index by index, the first step of every least-squares
/// alignment here. Throws AlignmentError if the sets differ in size or are empty.
struct PairedCentroids {
  Vec3 source = Vec3::Zero(), target = Vec3::Zero();
};
PairedCentroids pairedCentroids(const std::vector<Vec3>& source, const std::vector<Vec3>& target);

/// The similarity mapping `source` onto `target` in the least-squares sense (point k onto point k);
/// scale is fixed to 1 unless `with_scale`. Throws AlignmentError if the sets differ in size, are
/// empty, or their cross-covariance has rank below 2 (all points on one line).
Similarity3 umeyamaAlignment(const std::vector<Vec3>& source, const std::vector<Vec3>& target, bool with_scale);

}  // namespace livo::evaluate
