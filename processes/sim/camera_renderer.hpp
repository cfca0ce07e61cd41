// Renders camera images by casting one ray per pixel into the textured scene: Lambertian shading
// under the scene light, sky where nothing is hit, exposure that drifts over time (auto-exposure),
// optional motion blur (averaged sub-frames over the exposure), vignetting and sensor noise.
#pragma once

#include <vector>

#include "livo/sensor_rig.hpp"
#include "pinhole_camera.hpp"
#include "random.hpp"
#include "scene.hpp"
#include "sensor_data.hpp"
#include "trajectory.hpp"

namespace livo {
namespace sim {

struct CameraEffects {
  double exposure_time = 0.005;      // s, nominal
  double exposure_variation = 0.25;  // relative amplitude of the exposure drift (0 = constant)
  double exposure_period_s = 8.0;    // time scale of the drift
  int motion_blur_samples = 1;       // sub-frames averaged over the exposure (1 = no blur)
  double noise_std = 1.5;            // sensor noise, grey levels
  double brightness = 1.0;           // overall gain
  double vignetting = 0.25;          // brightness loss at the image corners (0..1)
};

class CameraRenderer {
 public:
  CameraRenderer(const CameraRig& rig, const CameraEffects& effects);

  /// The image whose exposure is centred on trajectory time `t_mid` (stamped `utime`).
  CameraImage render(const Scene& scene, const BodyTrajectory& trajectory, double t_mid, int64_t utime, Random rng) const;

  /// Exposure time at trajectory time t.
  double exposureAt(double t) const;
  const PinholeCamera& camera() const { return camera_; }

 private:
  void accumulate(const Scene& scene, const Pose3& T_W_C, float weight, std::vector<float>* rgb) const;
  Eigen::Vector3f shade(const Scene& scene, const Ray& ray, const RayHit& hit) const;

  /// A block of pixels whose rays all lie inside a pyramid (camera frame), used to cull the scene
  /// once per block instead of traversing it once per pixel.
  struct Tile {
    int x0, y0, x1, y1;   // pixel range [x0, x1) x [y0, y1)
    Vec3 normals[4];      // inward normals of the pyramid's planes through the optical centre
    bool culled = true;   // false if the tile is too wide for a pyramid
  };
  void buildTiles();

  CameraRig rig_;
  CameraEffects effects_;
  PinholeCamera camera_;
  std::vector<Eigen::Vector3f> rays_;  // unit ray per pixel, camera frame
  std::vector<float> vignette_;        // gain per pixel
  std::vector<Tile> tiles_;
};

}  // namespace sim
}  // namespace livo
