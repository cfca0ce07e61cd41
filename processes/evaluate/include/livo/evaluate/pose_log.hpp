// Poses recorded in an LCM log: livo.pose_t (e.g. GROUND_TRUTH) or livo.odometry_t (e.g. ODOMETRY).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

#include "livo/trajectory_io.hpp"

namespace livo::evaluate {

class PoseLogError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct PoseLog {
  Trajectory poses;       // sorted by stamp (utime in seconds); equal stamps keep log order
  std::string type_name;  // "livo.pose_t" or "livo.odometry_t"
};

/// A message's pose at its stamp (utime in seconds). Throws PoseLogError starting with `where` for a
/// non-finite pose or a quaternion whose norm is not about 1 (a corrupted or unset one).
StampedPose stampedPoseOf(int64_t utime, const double position[3], const double orientation[4],
                          const std::string& where);

/// True if the file starts with an LCM log event's sync word.
bool isLcmLog(const std::string& path);

/// Every message on `channel`, which must all be livo.pose_t or all livo.odometry_t (told apart
/// by their fingerprints). Throws PoseLogError naming the file and the event number (1-based, over
/// the whole log) for a message of another type, one that does not decode, or a non-finite or
/// zero-quaternion pose; and naming the channels present when `channel` has no message.
PoseLog readPoseLog(const std::string& path, const std::string& channel);

}  // namespace livo::evaluate
