// Least-squares alignment by a rotation about the world z axis (yaw) and a translation: the four
// degrees of freedom a visual- or LiDAR-inertial estimator cannot observe, since gravity fixes its
// roll and pitch. Both worlds must have z along gravity (up); the closed form is derived in
// four_dof_alignment.cpp.
#pragma once

#include <vector>

#include "livo/evaluate/umeyama.hpp"

namespace livo::evaluate {

/// The yaw and translation mapping `source` onto `target` in the least-squares sense (point k onto
/// point k), as a Similarity3 with scale 1 and a rotation about z. Throws AlignmentError if the sets
/// differ in size, are empty, or the yaw is undefined (every point on one vertical line).
Similarity3 fourDofAlignment(const std::vector<Vec3>& source, const std::vector<Vec3>& target);

/// The yaw in radians of a rotation about z (atan2(R(1,0), R(0,0))).
double yawOf(const Mat3& rotation_about_z);

}  // namespace livo::evaluate
