// One side of an evaluation, read from what the user named: a trajectory file (TUM, KITTI poses,
// EuRoC csv, told apart by trajectory_io) or an LCM log, optionally as "LOG:CHANNEL".
#pragma once

#include <stdexcept>
#include <string>

#include "livo/trajectory_io.hpp"

namespace livo::evaluate {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct TrajectoryInput {
  std::string spec;  // as given
  std::string path;
  std::string format;  // "tum", "kitti", "euroc-csv", or "lcmlog CHANNEL (livo.pose_t)"
  Trajectory poses;
  bool has_stamps = true;  // false for KITTI poses: stamps are line indices, pairing is by index
};

/// An input named as "FILE" or "LOG:CHANNEL".
struct LogSpec {
  std::string path;
  std::string channel;  // empty when not named (the caller's default, for an LCM log)
};

/// `spec` as a path and a channel: an existing file is the path as it is; else "PATH:CHANNEL" names
/// an LCM log and a channel. Throws InputError for no such file, an empty channel name, or a
/// channel named on a file that is not an LCM log.
LogSpec splitLogSpec(const std::string& spec);

/// Reads `spec`: an existing file is read whole (an LCM log on `default_channel`); otherwise
/// "PATH:CHANNEL" names an LCM log and a channel. KITTI pose rows are kept exactly as written
/// (their rotations are off SO(3) by ~1e-7, and evo evaluates them so). Throws (InputError, TrajectoryError or
/// PoseLogError) with the file, and the line or event where it applies; also for an empty
/// trajectory or a non-finite stamp.
TrajectoryInput readTrajectoryInput(const std::string& spec, const std::string& default_channel);

/// Moves every pose to a point rigidly attached to the body: p' = p + R * offset (the orientation
/// is kept), e.g. from the IMU to the prism a total station tracks.
void applyBodyOffset(Trajectory& poses, const Vec3& offset);

}  // namespace livo::evaluate
