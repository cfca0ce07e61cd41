// A car: the rear axle rolls along a planned path without slipping. The car body frame B (the
// wheel base frame: origin at the rear-axle centre, x forward, z up) has its origin on the path
// and its x axis along the path's horizontal tangent, so the rear axle's velocity is along the car's
// forward axis (the non-holonomic constraint); the body (IMU) frame I is mounted on the car at
// T_I_B, so a body origin ahead of the axle moves sideways by omega x lever arm in turns, as a
// real roof-mounted IMU does (kinematic bicycle model). The suspension shake (carShake) rocks the
// car about its rear axle and bobs it up and down on top. Every derivative is analytic.
// On graded ground (a Terrain) the four wheels stand on it: the car pitches with the grade between
// its axles and rolls with the slope between its left and right wheels (below), the shake on top.
#pragma once

#include <memory>

#include "livo/sim/paths.hpp"
#include "livo/sim/procedural_trajectory.hpp"
#include "livo/sim/terrain.hpp"
#include "livo/sim/trajectory.hpp"

namespace livo::sim {

struct CarTrajectoryOptions {
  double start_still_s = 2.0;             // stand still this long
  double ramp_s = 2.0;                    // then reach full speed over this long
  MotionShake shake;                      // position: of the rear axle (world); attitude: of the car about it
  Pose3 T_I_B = Pose3::Identity();        // the rear-axle frame in the body frame: the TRUE wheel base mounting
  std::shared_ptr<const Terrain> ground;  // null: the plane z = 0 (the path's z is absolute)
  double wheelbase = 2.7;                 // m, rear to front axle (on a ground)
  double track_width = 1.6;               // m, left to right wheel (on a ground)
};

/// The car frame B in the world and its first two time derivatives (without the body mounting).
struct CarFrame {
  Vec3 p = Vec3::Zero(), v = Vec3::Zero(), a = Vec3::Zero();         // the rear-axle centre
  Mat3 R = Mat3::Identity(), dR = Mat3::Zero(), ddR = Mat3::Zero();  // R_WB
};

class CarTrajectory : public BodyTrajectory {
 public:
  /// The path's horizontal track is the rear axle's; its height is the body origin's on a level car
  /// (the axle runs T_B_I's height below it). On a ground the path's z is the body origin's height
  /// above the ground on a level car (the rear axle's clearance is it less T_B_I's height).
  CarTrajectory(std::unique_ptr<Path> path, const CarTrajectoryOptions& options);
  BodyState at(double t) const override;
  CarFrame frame(double t) const;

 private:
  CarFrame levelFrame(double t) const;
  CarFrame gradedFrame(double t) const;

  std::unique_ptr<Path> path_;
  CarTrajectoryOptions options_;
  Vec3 p_BI_ = Vec3::Zero();  // body origin in B
};

}  // namespace livo::sim
