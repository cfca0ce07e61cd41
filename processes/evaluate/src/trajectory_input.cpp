#include "livo/evaluate/trajectory_input.hpp"

#include <sys/stat.h>
#include <cmath>

#include "livo/evaluate/pose_log.hpp"

namespace livo::evaluate {

namespace {
bool isRegularFile(const std::string& path) {
  struct stat st {};
  return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

const char* formatName(TrajectoryFormat f) {
  switch (f) {
    case TrajectoryFormat::kKitti: return "kitti";
    case TrajectoryFormat::kEurocCsv: return "euroc-csv";
    case TrajectoryFormat::kTum: break;
  }
  return "tum";
}
}  // namespace

LogSpec splitLogSpec(const std::string& spec) {
  if (isRegularFile(spec)) return LogSpec{spec, ""};
  const size_t colon = spec.rfind(':');
  if (colon == std::string::npos || colon == 0 || !isRegularFile(spec.substr(0, colon)))
    throw InputError(spec + ": no such file");
  LogSpec named{spec.substr(0, colon), spec.substr(colon + 1)};
  if (named.channel.empty()) throw InputError(spec + ": empty channel name after ':'");
  if (!isLcmLog(named.path)) throw InputError(spec + ": a channel was named, but " + named.path + " is not an LCM log");
  return named;
}

TrajectoryInput readTrajectoryInput(const std::string& spec, const std::string& default_channel) {
  TrajectoryInput in;
  in.spec = spec;
  const LogSpec named = splitLogSpec(spec);
  in.path = named.path;
  std::string channel = named.channel;

  if (isLcmLog(in.path)) {
    if (channel.empty()) channel = default_channel;
    PoseLog log = readPoseLog(in.path, channel);
    in.poses = std::move(log.poses);
    in.format = "lcmlog " + channel + " (" + log.type_name + ")";
  } else {
    const TrajectoryFormat format = detectTrajectoryFormat(in.path);
    in.format = formatName(format);
    in.has_stamps = format != TrajectoryFormat::kKitti;
    in.poses = readTrajectory(in.path);
  }
  if (in.poses.empty()) throw InputError(in.path + ": no poses");
  for (size_t i = 0; i < in.poses.size(); ++i) {
    if (!std::isfinite(in.poses[i].stamp))
      throw InputError(in.path + ": pose " + std::to_string(i + 1) + " has a non-finite time stamp");
    if (!in.poses[i].pose.matrix().allFinite())
      throw InputError(in.path + ": pose " + std::to_string(i + 1) + " is not finite");
  }
  return in;
}

void applyBodyOffset(Trajectory& poses, const Vec3& offset) {
  for (auto& s : poses) s.pose.translation() += s.pose.linear() * offset;
}

}  // namespace livo::evaluate
