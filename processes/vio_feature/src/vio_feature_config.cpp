#include "livo/vio_feature/vio_feature_config.hpp"

#include <ostream>

#include "livo/text_format.hpp"

namespace livo::vio_feature {

namespace {

/// What the rig (with a camera) sets: the channels, the camera and its extrinsic, the IMU noise, the
/// wheels; depth from the depth image and the LiDAR where the rig has them.
VioFeatureNodeOptions fromRig(const SensorRig& rig) {
  VioFeatureNodeOptions n;
  VioFeatureOptions& core = n.core;
  SlidingWindowOptions& w = core.window;
  core.camera = *rig.camera;
  n.imu_channel = rig.channels.imu;
  n.camera_channel = rig.channels.camera;
  n.depth_channel = rig.channels.depth;
  n.wheel_channel = rig.channels.wheel;
  w.T_I_C = rig.camera->T_I_C;
  w.camera_time_offset_s = rig.camera->time_offset_s;
  w.focal = 0.5 * (rig.camera->fx + rig.camera->fy);
  w.imu_noise = ImuPreintegrationNoise::fromRig(rig.imu);
  w.imu_noise.systematic_error_window_s = 1.0 / rig.camera->rate_hz;  // the states are the frames
  w.gravity = rig.imu.gravity;
  if (rig.wheel) {
    w.use_wheel = true;
    w.wheel_rig = *rig.wheel;
    w.wheel_noise = WheelPreintegrationNoise::fromRig(*rig.wheel);
  }
  core.use_depth_image = rig.camera->depth;
  core.use_lidar_depth = rig.lidar.has_value();
  return n;
}

/// vio_feature's name, channels, the sensors it uses of those the rig has, and how long an image
/// waits for them.
void readInputs(const Config& c, const SensorRig& rig, VioFeatureNodeOptions* n) {
  c.readOptional("name", n->name);
  const Config ch = c.optionalSection("channels");
  ch.readOptional("registered_scan", n->registered_scan_channel);
  ch.readOptional("visual_state", n->visual_state_channel);
  ch.readOptional("odometry", n->odometry_channel);
  bool flag = false;
  if (c.readOptional("wheel", flag)) n->core.window.use_wheel = flag && rig.wheel.has_value();
  if (c.readOptional("depth_image", flag)) n->core.use_depth_image = flag && rig.camera->depth;
  if (c.readOptional("lidar_depth", flag)) n->core.use_lidar_depth = flag && rig.lidar.has_value();
  c.readOptional("wheel_max_wait_s", n->wheel_max_wait_s);
  c.readOptional("depth_max_wait_s", n->depth_max_wait_s);
  c.readOptional("lidar_max_wait_s", n->lidar_max_wait_s);
  c.readOptional("lidar_depth_window_s", n->core.lidar_depth_window_s);
  c.readOptional("lidar_lag_s", n->core.lidar_lag_s);
}

/// The front end's keys (the KLT tracker).
void readTracker(const Config& c, FeatureTrackerOptions* t) {
  c.readOptional("tracked_features", t->max_features);
  c.readOptional("min_distance_px", t->min_distance_px);
  c.readOptional("ransac_threshold_px", t->ransac_threshold_px);
  c.readOptional("keyframe_parallax_px", t->keyframe_parallax_px);
}

/// The back end's keys (the sliding window); whether wheel_scale_std was given.
bool readWindow(const Config& c, SlidingWindowOptions* w) {
  c.readOptional("window_frames", w->window_frames);
  c.readOptional("graph_features", w->max_features);
  c.readOptional("pixel_sigma", w->pixel_sigma);
  c.readOptional("reprojection_cauchy", w->reprojection_cauchy);
  c.readOptional("depth_sigma_base", w->depth_sigma_base);
  c.readOptional("depth_sigma_relative", w->depth_sigma_relative);
  c.readOptional("solver_iterations", w->solver_iterations);
  c.readOptional("wheel_cauchy", w->wheel_cauchy);
  const bool scale_given = c.readOptional("wheel_scale_std", w->wheel_scale_std);
  c.readOptional("outlier_px", w->outlier_px);
  return scale_given;
}

/// Refuses out-of-range values, naming the key in `c` (the vio_feature section).
void checkRanges(const Config& c, const Config& root, const VioFeatureNodeOptions& n) {
  const VioFeatureOptions& core = n.core;
  const SlidingWindowOptions& w = core.window;
  auto fail = [&](const std::string& key, const std::string& what) { throw ConfigError(c.where(key) + ": " + what); };
  if (w.window_frames < 4) fail("window_frames", "must be >= 4");
  if (w.max_features < 1) fail("graph_features", "must be >= 1");
  if (core.tracker.max_features < 1) fail("tracked_features", "must be >= 1");
  if (!(core.tracker.min_distance_px > 0.0)) fail("min_distance_px", "must be > 0");
  if (!(core.tracker.ransac_threshold_px > 0.0)) fail("ransac_threshold_px", "must be > 0");
  if (!(core.tracker.keyframe_parallax_px > 0.0)) fail("keyframe_parallax_px", "must be > 0");
  if (!(w.pixel_sigma > 0.0)) fail("pixel_sigma", "must be > 0");
  if (!(w.reprojection_cauchy > 0.0)) fail("reprojection_cauchy", "must be > 0");
  if (!(w.depth_sigma_base > 0.0 && w.depth_sigma_relative >= 0.0))
    fail("depth_sigma_base", "depth_sigma_base must be > 0 and depth_sigma_relative >= 0");
  if (w.solver_iterations < 1) fail("solver_iterations", "must be >= 1");
  if (!(w.wheel_cauchy > 0.0)) fail("wheel_cauchy", "must be > 0");
  if (!(w.wheel_scale_std >= 0.0 && w.wheel_scale_std <= 0.2)) fail("wheel_scale_std", "must be in [0, 0.2]");
  if (!(w.outlier_px > 0.0)) fail("outlier_px", "must be > 0");
  if (!(n.wheel_max_wait_s >= 0.0 && n.depth_max_wait_s >= 0.0 && n.lidar_max_wait_s >= 0.0))
    fail("lidar_max_wait_s", "the waits must be >= 0");
  if (!(core.lidar_depth_window_s >= 0.0)) fail("lidar_depth_window_s", "must be >= 0");
  if (!(core.lidar_lag_s >= 0.0)) fail("lidar_lag_s", "must be >= 0");
  if (!(w.focal > 0.0)) throw ConfigError(root.where("rig") + ": the camera's fx and fy must be > 0");
}

}  // namespace

VioFeatureNodeOptions readVioFeatureNodeOptions(const Config& root) {
  const SensorRig rig = readSensorRig(root.section("rig"));
  if (!rig.camera) throw ConfigError(root.where("rig") + ": livo-vio-feature needs a rig.camera");
  VioFeatureNodeOptions n = fromRig(rig);
  bool scale_given = false;
  const Config c = root.optionalSection("vio_feature");
  if (!c.isNull()) {
    readInputs(c, rig, &n);
    readTracker(c, &n.core.tracker);
    scale_given = readWindow(c, &n.core.window);
    c.checkAllUsed();
  }
  SlidingWindowOptions& w = n.core.window;
  if (!scale_given)  // the tyres estimated only where measured depths make their scale observable
    w.wheel_scale_std = n.core.use_depth_image || n.core.use_lidar_depth ? kDepthWheelScaleStd : 0.0;
  checkRanges(c, root, n);
  return n;
}

void printOptions(const VioFeatureNodeOptions& n, std::ostream& os) {
  const VioFeatureOptions& core = n.core;
  const SlidingWindowOptions& w = core.window;
  os << "[" << n.name << "] inputs " << n.imu_channel << ", " << n.camera_channel
     << (core.use_depth_image ? ", " + n.depth_channel : std::string())
     << (w.use_wheel ? ", " + n.wheel_channel : std::string())
     << (core.use_lidar_depth ? ", " + n.registered_scan_channel : std::string()) << "; outputs "
     << n.visual_state_channel << ", " << n.odometry_channel << "\n"
     << "  camera " << core.camera.width << "x" << core.camera.height << " ("
     << distortionModelName(core.camera.distortion_model) << "); KLT " << core.tracker.max_features << " corners "
     << core.tracker.min_distance_px << " px apart, keyframes at " << core.tracker.keyframe_parallax_px
     << " px parallax\n"
     << "  window " << w.window_frames << " states, " << w.max_features << " features, " << w.solver_iterations
     << " solver iterations; factors: reprojection (sigma " << w.pixel_sigma << " px), IMU preintegration, bias walk"
     << (w.use_wheel ? ", " + wheelFactorText(w.wheel_rig, w.wheel_scale_std) : std::string()) << "; depth from "
     << (core.use_depth_image && core.use_lidar_depth ? "the depth image and the LiDAR"
         : core.use_depth_image                       ? "the depth image"
         : core.use_lidar_depth                       ? "the LiDAR"
                                                      : "triangulation only")
     << "\n";
}

}  // namespace livo::vio_feature
