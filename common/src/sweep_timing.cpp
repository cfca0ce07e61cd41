#include "livo/sweep_timing.hpp"

#include <algorithm>
#include <cmath>

#include "livo/time.hpp"

namespace livo {

double sweepEndOffset(const LidarScan& scan) {
  const double d = scan.sweep_duration;
  double end = std::isfinite(d) && d > 0.0 && d <= kMaxSweepDurationS ? d : 0.0;
  for (float t : scan.time_offset)
    if (std::isfinite(t) && t >= 0.0f && t <= kMaxSweepDurationS) end = std::max(end, static_cast<double>(t));
  return end;
}

SweepTiming sweepTiming(const LidarScan& scan, double lidar_time_offset_s) {
  SweepTiming s;
  s.end_offset_s = sweepEndOffset(scan);
  s.start_utime = scan.utime + toUtime(lidar_time_offset_s);
  s.end_utime = scan.utime + toUtime(lidar_time_offset_s + s.end_offset_s);
  return s;
}

}  // namespace livo
