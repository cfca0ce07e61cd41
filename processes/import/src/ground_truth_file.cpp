#include "livo/import/ground_truth_file.hpp"

#include "livo/import/stamp_conversion.hpp"
#include "livo/messages.hpp"
#include "livo/pose_t.hpp"
#include "livo/trajectory_io.hpp"

namespace livo::import {

int64_t importGroundTruthFile(const std::string& path, const std::string& channel, const std::string& child_frame,
                              SortedLogWriter& writer, ImportReport& report) {
  Trajectory traj;
  try {
    const TrajectoryFormat format = detectTrajectoryFormat(path);
    if (format == TrajectoryFormat::kKitti) {
      report.error(path + ": KITTI pose files carry no stamps; give a TUM or EuRoC csv file as ground truth");
      return 0;
    }
    traj = readTrajectory(path);
    report.metadataString("ground_truth_file", path);
  } catch (const std::exception& e) {
    report.error(std::string("ground truth: ") + e.what());
    return 0;
  }
  for (const StampedPose& p : traj) {
    pose_t m;
    m.utime = secondsToUtime(p.stamp);
    m.parent_frame = "W";
    m.child_frame = child_frame;
    poseTo(p.pose, m.position, m.orientation);
    writer.add(channel, m);
  }
  return static_cast<int64_t>(traj.size());
}

}  // namespace livo::import
