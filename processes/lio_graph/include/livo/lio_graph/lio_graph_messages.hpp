// Conversions between the LCM messages and livo-lio-graph's core types (as livo-lio's
// lio_messages.hpp). The sensor messages: livo/sensor_messages.hpp (fromMessage for imu_t,
// wheel_odometry_t and point_cloud_t); LOOP_CORRECTION: livo/loop_correction_message.hpp.
#pragma once

#include <cstdint>

#include "livo/keyframe_t.hpp"
#include "livo/lio_graph/lio_graph_estimator.hpp"
#include "livo/odometry_t.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/registered_scan_t.hpp"
#include "livo/visual_state_t.hpp"

namespace livo::lio_graph {

/// livo-vio-feature's VISUAL_STATE as the estimator takes it (time, pose, epoch).
VisualSample toVisualSample(const visual_state_t& m);
/// The output messages carry the frame they are in (epoch, correction_id).
odometry_t toOdometry(const GraphScanResult& r, const OdometryFrame& frame);
/// The deskewed sweep in frame "W" at the sweep end, with the input's times, rings and intensities
/// (livo/output_messages.hpp, as livo-lio publishes it).
registered_scan_t toRegisteredScan(const GraphScanResult& r, const point_cloud_t& input, const OdometryFrame& frame);
/// The keyframe's downsampled body-frame cloud with the input intensities (no increment: the graph
/// gives none).
keyframe_t toKeyframe(const GraphKeyframe& k, int16_t num_rings, const OdometryFrame& frame);

}  // namespace livo::lio_graph
