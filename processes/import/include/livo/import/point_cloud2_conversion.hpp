// sensor_msgs/PointCloud2 -> livo::point_cloud_t, interpreted by field names, datatypes and
// offsets. Understood layouts (any field order, any numeric datatype, either endianness):
//   coordinates  x, y, z (required)
//   intensity    intensity, else reflectivity, else signal
//   ring         ring (Velodyne, Ouster), channel, line (Livox)
//   time         time      relative to the stamp, float seconds (Velodyne)
//                t         relative, uint32 nanoseconds (Ouster)
//                offset_time relative, uint32 nanoseconds (Livox CustomMsg converted)
//                timestamp absolute, float64 seconds (Hesai, RoboSense) or nanoseconds (Livox
//                          driver 2; told apart by magnitude against the header stamp)
//   Integer time fields are nanoseconds, floating ones seconds, unless a unit is forced.
// Output: utime = sweep start (earliest of the stamp-derived start and the first point, floored
// to the microsecond), time_offset >= 0 seconds after it. Points with a non-finite coordinate,
// and the all-zero "no return" points of organised clouds, are skipped and counted.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "livo/import/ros_messages.hpp"
#include "livo/point_cloud_t.hpp"

namespace livo::import {

enum class LidarStampConvention {
  kStart,  // header.stamp is the sweep start (Ouster, most drivers)
  kEnd,    // header.stamp is the sweep end (NTU VIRAL): start = stamp - sweep_duration
};

struct PointCloudConversionOptions {
  LidarStampConvention stamp = LidarStampConvention::kStart;
  double sweep_duration = 0.1;  // seconds (10 Hz); raised to the largest offset if that exceeds it
  int num_rings = 0;            // 0: the organised height, else the largest ring + 1
  std::string time_field;       // "" = the first of time, t, offset_time, timestamp present
  std::string time_unit;        // "" = by datatype (integer ns, float s); else s, ms, us or ns
  int pattern = -1;             // -1: solid-state if a Livox field (offset_time, tag+line) is present
  std::string frame = "L";
  double max_relative_span_s = 1.0;  // per-point times spanning more than this mean wrong units
  /// A spinning LiDAR's cloud without a time field: per-point times from the azimuth (the sweep
  /// starts at the first point's azimuth and turns the way the points' order turns), as the KITTI
  /// importer does; false: every point at the sweep start.
  bool azimuth_times = true;
};

/// Per-point times (seconds after the sweep start) of a spinning LiDAR's points from their azimuth,
/// one turn per sweep. `order` is each point's place in the firing sequence (0..1: its column over
/// the width in an organised cloud, its index over the count in one in firing order); the net turn
/// along the points gives the direction (clockwise seen from above for Velodyne, Ouster, Hesai), the
/// first point and its place give the start azimuth, and the place decides the turn of points within
/// a hair of the start (the stagger of the first column). *clockwise tells which was found.
std::vector<float> azimuthTimeOffsets(const std::vector<float>& x, const std::vector<float>& y,
                                      const std::vector<float>& order, double sweep_duration,
                                      bool* clockwise = nullptr);

struct PointCloudConversion {
  point_cloud_t cloud;
  int64_t non_finite_points = 0;
  int64_t zero_points = 0;
  std::string layout;  // e.g. "x y z intensity t(uint32 ns, relative) ring"
};

/// Throws DecodeError naming `where` and the field for a missing coordinate field, a field
/// outside the point, data shorter than the declared size, or per-point times in a wrong unit.
PointCloudConversion convertPointCloud2(const RosPointCloud2& msg, const PointCloudConversionOptions& options,
                                        const std::string& where);

}  // namespace livo::import
