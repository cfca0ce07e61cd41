// Conversions between the LCM messages and livo-vio-feature's core types. The sensor messages:
// livo/sensor_messages.hpp (fromMessage for imu_t and wheel_odometry_t) and livo/camera_image.hpp
// (rawImage, decodeGrey, decodeDepth for image_t).
#pragma once

#include <cstdint>

#include "livo/odometry_t.hpp"
#include "livo/registered_scan_t.hpp"
#include "livo/vio_feature/vio_feature_estimator.hpp"
#include "livo/visual_state_t.hpp"

namespace livo::vio_feature {

/// A registered scan (checked by registeredScanProblem()) in the body frame at the sweep's end,
/// keeping the points in front of the camera: more than `min_depth` along its z (T_I_C: the
/// camera's extrinsic).
BodyScan toBodyScan(const registered_scan_t& m, const Pose3& T_I_C, double min_depth);
/// The state of an image that gave one, in the frame V's `epoch` (the coupling's message).
visual_state_t toVisualState(const FrameResult& r, int32_t epoch);
/// The same as odometry_t (parent V, child I), for the evaluation and the tools.
odometry_t toOdometry(const FrameResult& r, int32_t epoch);

}  // namespace livo::vio_feature
