// Validation of incoming messages shared by every process that consumes them.
#pragma once

#include <string>

#include "livo/registered_scan_t.hpp"

namespace livo {

/// Why a REGISTERED_SCAN cannot be used (empty cloud, arrays that disagree with num_points, a
/// non-finite pose, a cloud not in the world frame), or "" if it can.
std::string registeredScanProblem(const registered_scan_t& m);

/// Why a message pose cannot be used: non-finite numbers, or a quaternion (w, x, y, z) whose norm
/// is not within [0.5, 2] (poseFrom() normalises it); "" if it can.
std::string poseProblem(const double position[3], const double orientation_wxyz[4]);

}  // namespace livo
