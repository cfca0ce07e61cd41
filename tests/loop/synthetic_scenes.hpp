// Synthetic point clouds with exact answers for the loop-closure tests and benchmarks: an
// irregular outdoor-like scene (ground, walls at varied angles, boxes, poles, a slope), sampled
// as a LiDAR would see it from a viewpoint.
#pragma once

#include <cstdint>

#include "livo/loop/point_types.hpp"

namespace livo::loop::testing {

/// Dense surface samples of a 60 x 60 m scene; the same seed gives the same scene.
Points makeScene(uint32_t seed, double spacing = 0.1);

/// The scene points within `range` of `viewpoint`, expressed in a frame at `viewpoint` with yaw
/// `yaw` (a keyframe cloud), with Gaussian noise of `noise` m per axis.
Points viewFrom(const Points& scene, const Vec3& viewpoint, double yaw, double range, double noise, uint32_t seed);

/// A straight corridor (floor, ceiling, two walls, 3 x 3 m, 30 m long along x, 1 cm noise) seen
/// from x = x0: GICP fits it at any offset along the axis.
Points corridorView(double x0, uint32_t seed);

/// Pose with yaw about z and translation.
Pose3 yawPose(double yaw, const Vec3& t);

double rotationErrorDeg(const Pose3& a, const Pose3& b);
double translationError(const Pose3& a, const Pose3& b);

}  // namespace livo::loop::testing
