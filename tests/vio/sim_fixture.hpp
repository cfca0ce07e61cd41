// Rendered test data for the VIO from the simulator library (livo_sim): a sim config's scene,
// trajectory and rig; grey images rendered at trajectory times (exposure drift, vignetting, sensor
// noise as the simulator makes them) and LiDAR sweeps moved to the world frame with the true pose
// at each point's firing time (what a perfect LIO would publish as REGISTERED_SCAN).
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "livo/filter_state.hpp"
#include "livo/sim/camera_renderer.hpp"
#include "livo/sim/lidar_scanner.hpp"
#include "livo/sim/simulation_setup.hpp"
#include "livo/vio/grey_image.hpp"

namespace livo_test {

class SimScene {
 public:
  /// `config` relative to the source tree; `height` > 0 overrides the camera's image height
  /// (keeping the principal point centred), e.g. 512 for the 640x512 benchmark image;
  /// `lidar_model` (one of livo::sim::LidarPattern::models()) replaces the rig's LiDAR.
  explicit SimScene(const std::string& config = "config/sim/room.yaml", int height = 0,
                    const std::string& lidar_model = "") {
    livo::sim::SimOverrides ov;
    ov.duration_s = 30.0;
    setup_ = livo::sim::loadSimulation(std::string(LIVO_SOURCE_DIR) + "/" + config, ov);
    camera_ = *setup_.rig.camera;
    if (height > 0) {
      camera_.cy += 0.5 * (height - camera_.height);
      camera_.height = height;
    }
    if (!lidar_model.empty()) setup_.rig.lidar->model = lidar_model;
    renderer_ = std::make_unique<livo::sim::CameraRenderer>(camera_, setup_.options.camera);
    scanner_ = std::make_unique<livo::sim::LidarScanner>(*setup_.rig.lidar, setup_.options.lidar);
  }

  const livo::CameraRig& camera() const { return camera_; }
  /// From now on the images are rendered through the camera mounted with an error,
  /// T_I_C_true = T_I_C_rig * T_err; camera() stays the rig's (what an estimator believes).
  void mountCameraWithError(const livo::Pose3& T_err) {
    livo::CameraRig truth = camera_;
    truth.T_I_C = camera_.T_I_C * T_err;
    renderer_ = std::make_unique<livo::sim::CameraRenderer>(truth, setup_.options.camera);
  }
  const livo::sim::SimulationSetup& setup() const { return setup_; }
  int64_t utime(double t) const { return setup_.start_utime + static_cast<int64_t>(std::llround(t * 1e6)); }

  livo::Pose3 bodyPose(double t) const { return setup_.trajectory->at(t).T_W_I; }
  /// The body's angular rate at t (frame I): what lio sends with a prior (filter_state_t.angular_velocity).
  livo::Vec3 bodyRate(double t) const { return setup_.trajectory->at(t).angular_velocity; }
  /// The true body state at t with the rig's calibration (the camera's T_I_C and the LiDAR's T_I_L,
  /// no time shift): what a prior carries when the rig is exact.
  livo::FilterState trueState(double t) const {
    const auto s = setup_.trajectory->at(t);
    livo::FilterState x;
    x.rot = s.T_W_I.linear();
    x.pos = s.T_W_I.translation();
    x.vel = s.velocity;
    x.lidar = livo::SensorCalibration::fromPose(setup_.rig.lidar->T_I_L);
    x.camera = livo::SensorCalibration::fromPose(camera_.T_I_C);
    return x;
  }

  /// The simulator's image (8-bit grey) at trajectory time t, noise stream k; with `time_shift` the
  /// image is taken at t + time_shift but stamped t (a camera whose clock is off by -time_shift:
  /// FilterState::camera.dt = time_shift is the truth).
  livo::sim::CameraImage rendered(double t, uint64_t k, double time_shift = 0.0) const {
    return renderer_->render(*setup_.scene, *setup_.trajectory, t + time_shift, utime(t),
                             livo::sim::Random(setup_.options.seed, 7, k));
  }
  livo::vio::GreyImage image(double t, uint64_t k, double time_shift = 0.0) const {
    const livo::sim::CameraImage c = rendered(t, k, time_shift);
    livo::vio::GreyImage g;
    g.utime = c.utime;
    g.exposure_time = c.exposure_time;
    const cv::Mat view(c.height, c.width, c.color ? CV_8UC3 : CV_8UC1, const_cast<uint8_t*>(c.data.data()));
    if (c.color)
      cv::cvtColor(view, g.pixels, cv::COLOR_RGB2GRAY);
    else
      g.pixels = view.clone();
    return g;
  }

  /// World points of the sweep starting at trajectory time t (true pose per point).
  std::vector<livo::Vec3> sweep(double t, uint64_t k) const {
    const livo::sim::LidarSweep s =
        scanner_->scan(*setup_.scene, *setup_.trajectory, t, utime(t), t, livo::sim::Random(setup_.options.seed, 5, k));
    std::vector<livo::Vec3> out;
    out.reserve(s.size());
    for (size_t j = 0; j < s.size(); ++j) {
      const livo::Pose3 T_W_L = bodyPose(t + s.time_offset[j]) * setup_.rig.lidar->T_I_L;
      out.push_back(T_W_L * livo::Vec3(s.x[j], s.y[j], s.z[j]));
    }
    return out;
  }
  double sweepDuration() const { return scanner_->pattern().sweepDuration(); }

 private:
  livo::sim::SimulationSetup setup_;
  livo::CameraRig camera_;
  std::unique_ptr<livo::sim::CameraRenderer> renderer_;
  std::unique_ptr<livo::sim::LidarScanner> scanner_;
};

/// A prior covariance: rotation std rot_std (rad), position pos_std (m), the rest of the navigation
/// state loose; the LiDAR's and the camera's calibration held fixed (zero rows and columns: the rig's
/// values are exact unless a test gives them a prior, livo::setCalibrationPrior).
inline livo::StateCovariance priorCovariance(double rot_std, double pos_std) {
  livo::StateCovariance P = livo::StateCovariance::Zero();
  P.topLeftCorner<livo::FilterState::kNavDim, livo::FilterState::kNavDim>() = livo::Mat18::Identity() * 1e-2;
  P.block<3, 3>(0, 0) = livo::Mat3::Identity() * rot_std * rot_std;
  P.block<3, 3>(3, 3) = livo::Mat3::Identity() * pos_std * pos_std;
  P.block<3, 3>(6, 6) = livo::Mat3::Identity() * 0.05;
  return P;
}

}  // namespace livo_test
