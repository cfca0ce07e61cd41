// Renders camera images by casting one ray per pixel into the textured scene: Lambertian shading
// under the scene light, sky where nothing is hit, seen through glass, exposure that drifts over
// time, optional motion blur (averaged sub-frames over the exposure), optional rolling shutter
// (each row from the pose and scene at its own time), gain and exposure set by an auto-exposure
// controller (auto_exposure.hpp, run by the simulator frame after frame), vignetting and noise.
// The same rays give the exact z-depth of each pixel for an RGB-D camera (depth_effects.hpp adds
// what the depth sensor does to it).
#pragma once

#include <functional>
#include <vector>

#include "livo/sim/auto_exposure.hpp"

#include "livo/camera_projection.hpp"
#include "livo/sensor_rig.hpp"
#include "livo/sim/random.hpp"
#include "livo/sim/scene.hpp"
#include "livo/sim/sensor_data.hpp"
#include "livo/sim/trajectory.hpp"

namespace livo::sim {

struct CameraEffects {
  double exposure_time = 0.005;       // s, nominal
  double exposure_variation = 0.25;   // relative amplitude of the exposure drift (0 = constant)
  double exposure_period_s = 8.0;     // time scale of the drift
  int motion_blur_samples = 1;        // sub-frames averaged over the exposure (1 = no blur)
  double noise_std = 1.5;             // sensor noise, grey levels
  double brightness = 1.0;            // overall gain
  double vignetting = 0.25;           // brightness loss at the image corners (0..1)
  double rolling_shutter_s = 0.0;     // readout time, top row to bottom row (0 = global shutter)
  AutoExposureOptions auto_exposure;  // when enabled, exposure_variation drifts the scene light instead
};

class CameraRenderer {
 public:
  CameraRenderer(const CameraRig& rig, const CameraEffects& effects);

  /// The image whose exposure is centred on trajectory time `t_mid` (stamped `utime`).
  CameraImage render(const Scene& scene, const BodyTrajectory& trajectory, double t_mid, int64_t utime,
                     Random rng) const;
  /// The same with the exposure and gain an auto-exposure controller chose; with `z_depth`, also
  /// the exact depth along the optical axis per pixel (m, row-major; 0 where the ray meets nothing
  /// or glass first), from the rays of the sub-frame at t_mid (rows at their own times under a
  /// rolling shutter), so it is registered to the image. It leaves the image unchanged.
  CameraImage render(const Scene& scene, const BodyTrajectory& trajectory, double t_mid, int64_t utime, Random rng,
                     const ExposureSetting& setting, std::vector<float>* z_depth = nullptr) const;

  /// Exposure time at trajectory time t (the drift without auto exposure).
  double exposureAt(double t) const;
  /// Relative scene light at trajectory time t (the drift with auto exposure).
  double illuminationAt(double t) const;
  /// Time of row y's mid-exposure relative to the image stamp (the centre row's mid-exposure).
  double rowTimeOffset(int y) const;
  const CameraProjection& camera() const { return camera_; }

 private:
  using PoseAt = std::function<Pose3(double)>;
  /// Adds weight x the image seen at time t (each row at t + rowTimeOffset) to rgb, and, if
  /// `z_depth` is given, sets each pixel's z-depth; either may be null.
  void accumulate(const Scene& scene, const PoseAt& T_W_C_at, double t, uint64_t key, float weight,
                  std::vector<float>* rgb, std::vector<float>* z_depth) const;
  Eigen::Vector3f shade(const Scene& scene, const Ray& ray, const RayHit& hit) const;
  /// shade() behind glass surfaces: each mixes its own shade in by (1 - transmission).
  Eigen::Vector3f shadeThroughGlass(const Scene& scene, const Ray& ray, RayHit hit, const CastContext& context) const;

  /// A block of pixels whose rays all lie inside a pyramid (camera frame), used to cull the scene
  /// once per block instead of traversing it once per pixel.
  struct Tile {
    int x0, y0, x1, y1;  // pixel range [x0, x1) x [y0, y1)
    Vec3 normals[4];     // inward normals of the pyramid's planes through the optical centre
    bool culled = true;  // false if the tile is too wide for a pyramid
  };
  void buildTiles();

  CameraRig rig_;
  CameraEffects effects_;
  CameraProjection camera_;
  std::vector<Eigen::Vector3f> rays_;  // unit ray per pixel, camera frame
  std::vector<float> vignette_;        // gain per pixel
  std::vector<Tile> tiles_;
};

}  // namespace livo::sim
