#include "livo/sim/trajectory_config.hpp"

#include <sstream>

#include "livo/sim/car_trajectory.hpp"
#include "livo/sim/procedural_trajectory.hpp"
#include "livo/sim/recorded_trajectory.hpp"
#include "livo/trajectory_io.hpp"

namespace livo::sim {

namespace {

std::string resolve(const std::string& base_dir, const std::string& path) {
  if (path.empty() || path[0] == '/' || base_dir.empty()) return path;
  return base_dir + "/" + path;
}

std::vector<Vec3> readWaypoints(const Config& c) {
  const auto flat = c.get<std::vector<double>>("waypoints");
  if (flat.size() % 3 != 0 || flat.size() < 9)
    throw ConfigError(c.where("waypoints") + ": expected x, y, z triples of at least 3 waypoints");
  std::vector<Vec3> w;
  for (size_t i = 0; i < flat.size(); i += 3) w.emplace_back(flat[i], flat[i + 1], flat[i + 2]);
  return w;
}

double positive(const Config& c, const std::string& key, double value) {
  c.readOptional(key, value);
  if (!(value > 0.0)) throw ConfigError(c.where(key) + ": must be > 0");
  return value;
}

TrajectoryConfig readRecorded(const Config& c, const std::string& base_dir) {
  TrajectoryConfig out;
  const std::string gt_path = resolve(base_dir, c.get<std::string>("ground_truth"));
  std::string imu_path;
  if (c.readOptional("imu", imu_path)) imu_path = resolve(base_dir, imu_path);
  RecordedMotionOptions motion;
  c.readOptional("smoothing_s", motion.smoothing_s);
  c.readOptional("placement", motion.placement);
  c.readOptional("body_in_recorded", motion.body_in_recorded);
  c.readOptional("start_offset_s", out.recorded_start_offset_s);
  if (!(motion.smoothing_s >= 0.0)) throw ConfigError(c.where("smoothing_s") + ": must be >= 0");
  if (!(out.recorded_start_offset_s >= 0.0)) throw ConfigError(c.where("start_offset_s") + ": must be >= 0");
  livo::Trajectory poses;
  try {
    poses = livo::readTrajectory(gt_path);
  } catch (const std::exception& e) {
    throw ConfigError(c.where("ground_truth") + ": " + e.what());
  }
  if (!imu_path.empty()) {
    try {
      out.recorded_imu = readAslImuCsv(imu_path);
    } catch (const std::exception& e) {
      throw ConfigError(c.where("imu") + ": " + e.what());
    }
    if (out.recorded_imu.empty()) throw ConfigError(c.where("imu") + ": " + imu_path + " holds no samples");
  }
  if (poses.size() < 4) throw ConfigError(c.where("ground_truth") + ": " + gt_path + " holds fewer than 4 poses");
  // interpolation needs increasing stamps; a least-squares fit takes repeated ones
  const bool smoothing = motion.smoothing_s > 0.0;
  for (size_t i = 1; i < poses.size(); ++i)
    if (poses[i].stamp < poses[i - 1].stamp || (!smoothing && poses[i].stamp == poses[i - 1].stamp))
      throw ConfigError(c.where("ground_truth") + ": " + gt_path + ": stamps do not increase at pose " +
                        std::to_string(i) + (smoothing ? "" : " (smoothing_s > 0 accepts repeated stamps)"));
  if (smoothing && !(motion.smoothing_s < poses.back().stamp - poses.front().stamp))
    throw ConfigError(c.where("smoothing_s") + ": must be shorter than the recording");
  auto rec = std::make_unique<RecordedTrajectory>(poses, motion);
  out.recorded_start_stamp = rec->startStamp();
  std::ostringstream os;
  os << "recorded: " << poses.size() << " poses from " << gt_path << " (" << rec->duration() << " s), ";
  if (smoothing)
    os << "least-squares cubic B-spline, knots every " << motion.smoothing_s << " s";
  else
    os << "natural cubic splines through the poses";
  if (!motion.placement.matrix().isIdentity(0.0) || !motion.body_in_recorded.matrix().isIdentity(0.0))
    os << ", T_W_I = placement * T_recorded * body_in_recorded";
  if (out.recorded_imu.empty())
    os << "; IMU synthesised from the motion";
  else
    os << "; " << out.recorded_imu.size() << " IMU samples from " << imu_path;
  out.description = os.str();
  out.trajectory = std::move(rec);
  out.recorded = true;
  return out;
}

/// A path and the words that describe it (livo-sim's print-out).
struct DescribedPath {
  std::unique_ptr<Path> path;
  std::string description;
};

/// handheld / car: a closed loop through `waypoints` at about `speed`, heading along the path; the
/// shake of a walker or a car; a car's `wheelbase` and `track_width` (kept as given when absent).
DescribedPath readLoop(const Config& c, const std::string& type, double shake, ProceduralTrajectoryOptions* o,
                       double* wheelbase, double* track_width) {
  const bool car = type == "car";
  const std::vector<Vec3> waypoints = readWaypoints(c);
  const double speed = positive(c, "speed", car ? 6.0 : 1.2);
  const double spacing = positive(c, "control_spacing", car ? 4.0 : 1.0);
  DescribedPath out;
  std::ostringstream os;
  try {
    auto loop = std::make_unique<BSplineLoopPath>(waypoints, speed, spacing);
    os << type << ": closed loop through " << waypoints.size() << " waypoints, about " << speed << " m/s, "
       << loop->period() << " s per lap";
    out.path = std::move(loop);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(c.where("waypoints") + ": " + e.what());
  }
  o->attitude = AttitudeMode::kFollowHeading;
  o->shake = car ? carShake(shake) : handheldShake(shake);
  if (car) {
    *wheelbase = positive(c, "wheelbase", *wheelbase);
    *track_width = positive(c, "track_width", *track_width);
  }
  out.description = os.str();
  return out;
}

/// uav: a Lissajous flight around `center` with a thrust-aligned attitude and its own yaw motion.
DescribedPath readLissajous(const Config& c, double shake, ProceduralTrajectoryOptions* o) {
  const Vec3 center = c.get<Vec3>("center");
  const Vec3 amplitude = c.get<Vec3>("amplitude");
  const Vec3 frequency = c.get<Vec3>("frequency_hz");
  Vec3 phase_deg = Vec3::Zero();
  c.readOptional("phase_deg", phase_deg);
  double yaw_rate_deg = 20.0, yaw_amplitude_deg = 0.0, yaw_frequency = 0.1;
  c.readOptional("yaw_rate_deg", yaw_rate_deg);
  c.readOptional("yaw_amplitude_deg", yaw_amplitude_deg);
  c.readOptional("yaw_frequency_hz", yaw_frequency);
  DescribedPath out;
  out.path = std::make_unique<LissajousPath>(center, amplitude, frequency, phase_deg * M_PI / 180.0);
  o->attitude = AttitudeMode::kThrustAligned;
  o->yaw_rate = yaw_rate_deg * M_PI / 180.0;
  o->yaw_wave = {yaw_amplitude_deg * M_PI / 180.0, yaw_frequency, 0.0};
  o->shake = flightShake(shake);
  std::ostringstream os;
  os << "uav: Lissajous flight around [" << center.transpose() << "], amplitude [" << amplitude.transpose()
     << "] m, frequencies [" << frequency.transpose() << "] Hz, thrust-aligned attitude";
  out.description = os.str();
  return out;
}

}  // namespace

TrajectoryConfig readTrajectoryConfig(const Config& c, double gravity, const std::string& base_dir,
                                      const Pose3& T_I_rear_axle, std::shared_ptr<const Terrain> ground,
                                      double track_width) {
  const std::string type = c.get<std::string>("type");
  if (type == "recorded") {
    TrajectoryConfig out = readRecorded(c, base_dir);
    c.checkAllUsed();
    return out;
  }
  ProceduralTrajectoryOptions o;
  o.gravity = gravity;
  o.start_still_s = 2.0;
  o.ramp_s = 2.0;
  c.readOptional("start_still_s", o.start_still_s);
  c.readOptional("ramp_s", o.ramp_s);
  if (o.start_still_s < 0.0) throw ConfigError(c.where("start_still_s") + ": must be >= 0");
  if (o.ramp_s < 0.0) throw ConfigError(c.where("ramp_s") + ": must be >= 0");
  double shake = 1.0;
  c.readOptional("shake", shake);
  if (shake < 0.0) throw ConfigError(c.where("shake") + ": must be >= 0");

  double wheelbase = CarTrajectoryOptions().wheelbase;
  DescribedPath described;
  if (type == "handheld" || type == "car") {
    described = readLoop(c, type, shake, &o, &wheelbase, &track_width);
  } else if (type == "uav") {
    described = readLissajous(c, shake, &o);
  } else {
    throw ConfigError(c.where("type") + ": unknown trajectory type '" + type +
                      "' (known: handheld, car, uav, recorded)");
  }
  std::unique_ptr<Path> path = std::move(described.path);
  std::ostringstream os;
  os << described.description;
  c.checkAllUsed();
  os << ", still for " << o.start_still_s << " s then a " << o.ramp_s << " s ramp, shake x" << shake;
  TrajectoryConfig out;
  if (type == "car") {
    const Vec3 p_BI = T_I_rear_axle.inverse().translation();
    os << "; rear axle " << p_BI.x() << " m behind and " << p_BI.z() << " m below the body origin";
    if (ground)
      os << "; on the scene's terrain (grades at most " << ground->maxGrade() * 100.0 << " %, wheelbase " << wheelbase
         << " m, track " << track_width << " m)";
    out.trajectory = std::make_unique<CarTrajectory>(
        std::move(path),
        CarTrajectoryOptions{o.start_still_s, o.ramp_s, o.shake, T_I_rear_axle, ground, wheelbase, track_width});
  } else {
    out.trajectory = std::make_unique<ProceduralTrajectory>(std::move(path), o);
  }
  out.description = os.str();
  return out;
}

}  // namespace livo::sim
