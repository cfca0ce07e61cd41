// A car: the rear axle rolls along a planned path without slipping. The car body frame B (the
// wheel base frame: origin at the rear-axle centre, x forward, z up) has its origin on the path
// and its x axis along the path's horizontal tangent, so the rear axle's velocity is along the car's
// forward axis (the non-holonomic constraint); the body (IMU) frame I is mounted on the car at
// T_I_B, so a body origin ahead of the axle moves sideways by omega x lever arm in turns, as a
// real roof-mounted IMU does (kinematic bicycle model). The suspension shake (carShake) rocks the
// car about its rear axle and bobs it up and down on top. Every derivative is analytic.
#pragma once

#include <memory>

#include "livo/sim/paths.hpp"
#include "livo/sim/procedural_trajectory.hpp"
#include "livo/sim/trajectory.hpp"

namespace livo::sim {

struct CarTrajectoryOptions {
  double start_still_s = 2.0;          // stand still this long
  double ramp_s = 2.0;                 // then reach full speed over this long
  MotionShake shake;                   // position: of the rear axle (world); attitude: of the car about it
  Pose3 T_I_B = Pose3::Identity();     // the rear-axle frame in the body frame: the TRUE wheel base mounting
};

class CarTrajectory : public BodyTrajectory {
 public:
  /// The path's horizontal track is the rear axle's; its height is the body origin's on a level car
  /// (the axle runs T_B_I's height below it).
  CarTrajectory(std::unique_ptr<Path> path, const CarTrajectoryOptions& options);
  BodyState at(double t) const override;

 private:
  std::unique_ptr<Path> path_;
  CarTrajectoryOptions options_;
  Vec3 p_BI_ = Vec3::Zero();  // body origin in B
};

}  // namespace livo::sim
