// livo-vio-feature's back end: a sliding window of camera-rate states (pose, velocity, biases)
// optimised with Ceres over
//   - reprojection factors of tracked features (inverse depth in their first frame, Cauchy loss),
//   - inverse-depth priors where a depth was measured (RGB-D depth image or LiDAR),
//   - IMU preintegration and bias random-walk factors between consecutive states,
//   - wheel preintegration factors (Cauchy loss) when the rig has a wheel encoder, corrected to
//     first order in the tyres' scales [s_l, s_r] (true radius over the nominal), one parameter
//     block for the whole run with a prior of sigma wheel_scale_std around 1 (as livo-lio-graph's),
//     and, where the rig states its uncertainty (rig.wheel.calibration_std), through the wheel
//     frame's mounting rotation, likewise a block for the whole run with that prior around the rig's,
//   - the marginal prior of the states and features that left the window (and, the scale and
//     mounting blocks never leaving, what they said about them)
// (VINS-Mono's scheme, the wheel as in Ground-Fusion, from common/'s preintegration and factors).
// When the window is full, a new keyframe pushes the oldest state out (marginalised: its factors
// become the prior); a new frame that is not a keyframe replaces the previous newest, whose
// observations are dropped and whose IMU and wheel intervals merge into the new one's.
//
// Initialisation: at rest from the IMU (gravity, gyro bias), or in motion from the wheels (the
// body velocity from the wheel speeds, gravity from the specific force over a short window less
// the acceleration the wheels and the gyro account for). The world is gravity-aligned, z up, with
// the first state at the origin and zero yaw.
//
// The core knows nothing of LCM or images: features arrive tracked and undistorted (the front end,
// feature_tracker.hpp), IMU and wheel samples on the IMU clock.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "livo/marginalization.hpp"
#include "livo/sensor_samples.hpp"
#include "livo/start_state_prior.hpp"
#include "livo/vio_feature/vio_feature_options.hpp"

namespace livo::vio_feature {

/// One tracked feature in one image: its track's id, its undistorted normalised point (z = 1) and
/// its measured depth along the camera's z (0: none).
struct FeatureMeasurement {
  uint64_t id = 0;
  Vec2 xy = Vec2::Zero();
  double depth = 0.0;
};

/// The features of one image, stamped on the camera clock.
struct FrameFeatures {
  int64_t utime = 0;
  bool keyframe = true;  // the front end's decision (parallax, tracked count)
  std::vector<FeatureMeasurement> features;
};

/// The estimate at an image's time (IMU clock).
struct VisualState {
  int64_t utime = 0;
  Pose3 pose = Pose3::Identity();  // W_T_I
  Vec3 velocity = Vec3::Zero();    // W
  Vec3 gyro_bias = Vec3::Zero();
  Vec3 accel_bias = Vec3::Zero();
  Mat6 pose_covariance = Mat6::Identity();  // [dtheta (right), dp]
};

struct FrameResult {
  enum class Status { kRejected, kInitializing, kInitialized, kTracked };
  Status status = Status::kRejected;
  std::string note;
  VisualState state;                   // kInitialized, kTracked
  int features_in_graph = 0;           // with an inverse depth and two observations or more
  int features_with_depth = 0;         // of those, with a measured depth
  int outliers = 0;                    // dropped after this optimisation
  bool static_start = false;           // kInitialized: at rest, else in motion (wheels)
  Vec2 wheel_scale = Vec2::Ones();     // kInitialized, kTracked: [left, right] tyre radius over the nominal
  Vec3 wheel_mounting = Vec3::Zero();  // kInitialized, kTracked: the wheel frame's mounting correction (rad)
};

const char* statusName(FrameResult::Status s);

class SlidingWindowEstimator {
 public:
  explicit SlidingWindowEstimator(const SlidingWindowOptions& options);
  ~SlidingWindowEstimator();
  SlidingWindowEstimator(const SlidingWindowEstimator&) = delete;
  SlidingWindowEstimator& operator=(const SlidingWindowEstimator&) = delete;

  /// Buffers an IMU sample (IMU clock); false with `why` for a non-finite or non-increasing one.
  bool addImu(const ImuSample& s, std::string* why = nullptr);
  /// Buffers a wheel reading (IMU clock); the same checks.
  bool addWheel(const WheelSample& s, std::string* why = nullptr);
  /// Processes an image's features. The IMU (and the wheels) must already be buffered up to the
  /// image's time on the IMU clock (utime + camera_time_offset_s), else the frame is refused.
  FrameResult addFrame(const FrameFeatures& frame);

  bool initialized() const { return !window_.empty(); }
  /// W_T_I at time t (IMU clock): between two window states (interpolated), or after the newest
  /// (the IMU's prediction from it). False before initialisation, before the oldest state or past
  /// the buffered IMU.
  bool poseAt(int64_t t, Pose3* pose) const;
  /// The body's rotation from t0 to t1 (R_I0_I1) integrated from the gyro, less the newest state's
  /// bias (none before initialisation); false where the IMU does not cover [t0, t1].
  bool gyroRotation(int64_t t0, int64_t t1, Mat3* R) const;
  /// Drops the window, the features and the prior (the buffers stay): the next frames initialise.
  /// The tyre scales and the wheel mounting learnt so far stay: the next window's priors are
  /// centred on them.
  void reset();
  /// The tyres' scales [left, right] (true radius over the nominal): estimated when
  /// estimatesWheelScale(), else [1, 1].
  Vec2 wheelScale() const { return Vec2(wheel_scale_[0], wheel_scale_[1]); }
  bool estimatesWheelScale() const { return options_.use_wheel && options_.wheel_scale_std > 0.0; }
  /// The wheel frame's mounting correction δ (rad): R_IO = R_IB Exp(δ) (wheel_preintegration.hpp),
  /// estimated when estimatesWheelMounting() (the rig states its rotation's uncertainty), else zero.
  Vec3 wheelMounting() const { return Vec3(wheel_mounting_[0], wheel_mounting_[1], wheel_mounting_[2]); }
  bool estimatesWheelMounting() const { return options_.use_wheel && options_.wheel_rig.estimatesMounting(); }
  /// The newest IMU sample's time (0 before any).
  int64_t imuWatermark() const { return imu_.empty() ? 0 : imu_.back().utime; }
  int64_t wheelWatermark() const { return wheel_.empty() ? 0 : wheel_.back().utime; }
  const SlidingWindowOptions& options() const { return options_; }

 private:
  struct Frame;
  struct Feature;

  bool initialize(int64_t t, const FrameFeatures& frame, FrameResult* res);
  /// `camera_still`: the image says the body is at rest, so the IMU's own stillness test (which a
  /// vibrating platform, a drone on its rotors, fails) is waived.
  bool initializeAtRest(int64_t t, bool camera_still, FrameResult* res);
  /// True if the features have not moved (median under still_parallax_px) since an image at least
  /// init.window_s older; keeps the images of that span.
  bool cameraStill(int64_t t, const FrameFeatures& frame);
  bool initializeMoving(int64_t t, FrameResult* res);
  /// The first state and its priors (the gauge held, the rest with `sigma`), the calibration
  /// blocks' priors around what an earlier epoch learnt.
  void startWindow(int64_t t, const Mat3& R, const Vec3& v, const Vec3& bg, const Vec3& ba,
                   const StartStateSigmas& sigma);
  /// The IMU (and wheel) factors of `to` from `from`'s time, linearised at from's biases; false if
  /// the IMU does not cover the interval or has a gap.
  /// `predict`: the new state's first guess is the IMU's prediction (else it keeps its estimate).
  bool connect(Frame& from, Frame& to, bool predict, std::string* why);
  void addObservations(Frame& frame, const FrameFeatures& features);
  void triangulate();
  /// The features that enter the optimisation (inverse depth known, two frames or more).
  std::vector<Feature*> graphFeatures();
  /// Every factor of the window: the marginal prior, the first state's priors, the IMU, bias-walk
  /// and wheel factors, the features' reprojections and depth priors, as add(cost, loss, blocks).
  template <class Add>
  void forEachFactor(const std::vector<Feature*>& features, Add&& add) const;
  void optimize(const std::vector<Feature*>& features);
  /// Drops the features of the last optimisation that are off by more than outlier_px anywhere.
  int rejectOutliers();
  void marginalizeOldest();
  void dropSecondNewest();
  void eraseFeature(uint64_t id);
  Mat6 newestPoseCovariance(const std::vector<Feature*>& features) const;
  VisualState stateOf(const Frame& f) const;
  /// The parameter blocks of b's wheel factor (from a): the poses, and the scales and the mounting
  /// if estimated.
  std::vector<double*> wheelBlocks(Frame& a, Frame& b) const;

  SlidingWindowOptions options_;
  Vec3 gravity_W_;
  std::deque<ImuSample> imu_;
  std::deque<WheelSample> wheel_;
  std::deque<std::unique_ptr<Frame>> window_;
  std::map<uint64_t, std::unique_ptr<Feature>> features_;
  std::set<uint64_t> rejected_;
  std::deque<std::pair<int64_t, std::map<uint64_t, Vec2>>>
      recent_;  // before initialisation: t, features  // outlier tracks: their later observations are ignored
  std::shared_ptr<MarginalPrior> prior_;
  std::unique_ptr<ceres::CostFunction> prior_factor_;
  std::unique_ptr<ceres::LossFunction> reprojection_loss_;
  // [s_l, s_r]: a parameter block for as long as the estimator lives (never marginalised, kept
  // across reset()); mutable as the const walks over the factors hand Ceres its pointer.
  mutable double wheel_scale_[2] = {1.0, 1.0};
  mutable double wheel_mounting_[3] = {0.0, 0.0, 0.0};  // δ, likewise
};

}  // namespace livo::vio_feature
