// Rendered test data for the feature front end from the simulator library (livo_sim): a scene, a
// trajectory and a camera rig (a sim config's, or built by a test), grey images rendered at
// trajectory times with the simulator's noise and exposure drift, and the truth to check tracks
// against: the scene point a pixel's ray hits, and where a world point lands in a later image.
// For an RGB-D rig (rig.camera.depth), the depth image registered to each grey image, with the
// simulator's depth-sensor effects (sim.depth), as livo-sim logs it on DEPTH.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "livo/sensor_samples.hpp"
#include "livo/sim/camera_renderer.hpp"
#include "livo/sim/depth_effects.hpp"
#include "livo/sim/simulation_setup.hpp"

namespace livo_test {

class RenderedSequence {
 public:
  /// A sim config's scene, trajectory, camera and camera effects (`config` relative to the source tree).
  explicit RenderedSequence(const std::string& config = "config/sim/room.yaml") {
    livo::sim::SimOverrides ov;
    ov.duration_s = 30.0;
    livo::sim::SimulationSetup setup = livo::sim::loadSimulation(std::string(LIVO_SOURCE_DIR) + "/" + config, ov);
    camera_ = *setup.rig.camera;
    seed_ = setup.options.seed;
    start_utime_ = setup.start_utime;
    effects_ = setup.options.camera;
    depth_effects_ = setup.options.depth;
    scene_ = std::move(setup.scene);
    trajectory_ = std::move(setup.trajectory);
    renderer_ = std::make_unique<livo::sim::CameraRenderer>(camera_, effects_);
  }
  /// A scene and trajectory of a test's own.
  RenderedSequence(std::unique_ptr<livo::sim::Scene> scene, std::unique_ptr<livo::sim::BodyTrajectory> trajectory,
                   const livo::CameraRig& camera, const livo::sim::CameraEffects& effects)
      : camera_(camera),
        effects_(effects),
        scene_(std::move(scene)),
        trajectory_(std::move(trajectory)),
        renderer_(std::make_unique<livo::sim::CameraRenderer>(camera, effects)) {}

  /// From now on renders (and answers for) another camera in the same mount: its size,
  /// intrinsics and distortion; T_I_C stays.
  void setLens(livo::CameraRig lens) {
    lens.T_I_C = camera_.T_I_C;
    camera_ = lens;
    renderer_ = std::make_unique<livo::sim::CameraRenderer>(camera_, effects_);
  }

  const livo::CameraRig& camera() const { return camera_; }
  const livo::sim::Scene& scene() const { return *scene_; }
  int64_t utime(double t) const { return start_utime_ + static_cast<int64_t>(std::llround(t * 1e6)); }

  /// The grey image at trajectory time t (noise stream k).
  cv::Mat image(double t, uint64_t k = 0) const {
    const livo::sim::CameraImage c =
        renderer_->render(*scene_, *trajectory_, t, utime(t), livo::sim::Random(seed_, 7, k));
    const cv::Mat view(c.height, c.width, c.color ? CV_8UC3 : CV_8UC1, const_cast<uint8_t*>(c.data.data()));
    return view.clone();
  }

  /// The grey image at trajectory time t (noise stream k) and its depth image: CV_32F metres along
  /// z, 0 where the sensor gives none (the simulator's millimetres, as livo-vio-feature decodes them).
  void imageAndDepth(double t, uint64_t k, cv::Mat* grey, cv::Mat* depth) const {
    std::vector<float> z;
    const livo::sim::ExposureSetting setting{renderer_->exposureAt(t), 1.0};
    const livo::sim::CameraImage c =
        renderer_->render(*scene_, *trajectory_, t, utime(t), livo::sim::Random(seed_, 7, k), setting, &z);
    *grey = cv::Mat(c.height, c.width, c.color ? CV_8UC3 : CV_8UC1, const_cast<uint8_t*>(c.data.data())).clone();
    std::vector<uint16_t> mm =
        livo::sim::measureDepth(z, c.width, c.height, depth_effects_, livo::sim::Random(seed_, 8, k));
    cv::Mat(c.height, c.width, CV_16UC1, mm.data()).convertTo(*depth, CV_32F, 1e-3);
  }

  const livo::sim::BodyTrajectory& trajectory() const { return *trajectory_; }
  livo::Pose3 cameraPose(double t) const { return trajectory_->at(t).T_W_I * camera_.T_I_C; }
  /// Rotation from the camera frame at t_prev to the one at t (what a gyro integrates).
  livo::Mat3 rotationCurPrev(double t, double t_prev) const {
    return cameraPose(t).linear().transpose() * cameraPose(t_prev).linear();
  }

  /// The world point the ray through `pixel` hits at time t, and the object it is on; false for sky.
  bool pointAt(const Eigen::Vector2d& pixel, double t, livo::Vec3* p_W, int* object = nullptr) const {
    const livo::Pose3 T_W_C = cameraPose(t);
    livo::sim::Ray ray;
    ray.origin = T_W_C.translation();
    ray.direction = T_W_C.linear() * renderer_->camera().pixelRay(pixel);
    const livo::sim::RayHit hit = scene_->cast(ray, livo::sim::CastContext::camera(t, 0));
    if (!hit.valid()) return false;
    *p_W = ray.origin + hit.t * ray.direction;
    if (object) *object = hit.object;
    return true;
  }
  /// The pixel of world point p_W at time t; false if behind the camera or hidden by a nearer surface.
  bool visiblePixel(const livo::Vec3& p_W, double t, Eigen::Vector2d* pixel) const {
    const livo::Pose3 T_W_C = cameraPose(t);
    if (!renderer_->camera().project(T_W_C.inverse() * p_W, pixel)) return false;
    livo::sim::Ray ray;
    ray.origin = T_W_C.translation();
    const livo::Vec3 d = p_W - ray.origin;
    ray.direction = d.normalized();
    const livo::sim::RayHit hit = scene_->cast(ray, livo::sim::CastContext::camera(t, 0));
    return !hit.valid() || hit.t > d.norm() - 0.01;
  }

 private:
  livo::CameraRig camera_;
  livo::sim::CameraEffects effects_;
  livo::sim::DepthEffects depth_effects_;
  uint64_t seed_ = 1;
  int64_t start_utime_ = 1'700'000'000'000'000;
  std::unique_ptr<livo::sim::Scene> scene_;
  std::unique_ptr<livo::sim::BodyTrajectory> trajectory_;
  std::unique_ptr<livo::sim::CameraRenderer> renderer_;
};

/// The trajectory's exact IMU sample at trajectory time t (gyro = angular velocity, accel =
/// R^T (a + g)), stamped on the sequence's clock.
inline livo::ImuSample exactImu(const RenderedSequence& seq, double t) {
  const livo::sim::BodyState s = seq.trajectory().at(t);
  livo::ImuSample m;
  m.utime = seq.utime(t);
  m.gyro = s.angular_velocity;
  m.accel = s.T_W_I.linear().transpose() * (s.acceleration + livo::Vec3(0.0, 0.0, 9.81));
  return m;
}

}  // namespace livo_test
