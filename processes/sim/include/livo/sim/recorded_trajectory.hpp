// Motion of a real recording: ground-truth poses (e.g. 20 Hz Vicon, 300 Hz motion capture) placed
// in the scene and turned into body poses, then either interpolated by natural cubic splines (C2)
// in position and in the sign-aligned quaternion (normalised), or, for jittery samples, fitted by a
// least-squares cubic B-spline (sample_curves.hpp) that then is the motion. Either way a LiDAR or a
// camera can be placed, and an IMU sampled, at any instant along the real motion.
#pragma once

#include <memory>
#include <vector>

#include "livo/sim/sample_curves.hpp"
#include "livo/sim/trajectory.hpp"
#include "livo/trajectory_io.hpp"

namespace livo::sim {

struct RecordedMotionOptions {
  /// 0: natural cubic splines through the poses; > 0: least-squares cubic B-spline with knots at
  /// most this many seconds apart (a low-pass of about 1 / (2 smoothing_s) Hz).
  double smoothing_s = 0.0;
  /// T_W_M: the recording's reference frame M (its world, e.g. the motion-capture frame) in the scene.
  Pose3 placement = Pose3::Identity();
  /// T_R_I: the body (IMU) frame I in the recorded frame R (the frame the poses are of).
  Pose3 body_in_recorded = Pose3::Identity();
};

/// Body poses from recorded poses T_M_R: T_W_I = placement * T_M_R * body_in_recorded, stamps kept.
livo::Trajectory placeRecording(const livo::Trajectory& poses, const Pose3& placement, const Pose3& body_in_recorded);

class RecordedTrajectory : public BodyTrajectory {
 public:
  /// `poses` must hold at least 4 poses with increasing stamps (non-decreasing when smoothing);
  /// time 0 is the first stamp.
  explicit RecordedTrajectory(const livo::Trajectory& poses, const RecordedMotionOptions& options = {});
  BodyState at(double t) const override;
  double duration() const override { return duration_; }
  double startStamp() const { return start_stamp_; }

 private:
  static std::vector<double> times(const livo::Trajectory& poses);
  static std::vector<SampledCurve::Value> values(const livo::Trajectory& poses);
  double start_stamp_ = 0.0, duration_ = 0.0;
  std::unique_ptr<SampledCurve> curve_;
};

}  // namespace livo::sim
