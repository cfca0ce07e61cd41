// Motion undistortion by backward propagation (FAST-LIO's scheme, paper sec. 2.4.1): a point
// measured at time t_j is moved into the body frame at the scan end using the IMU-rate trajectory
// of the propagation (constant rate and acceleration within each IMU step).
#pragma once

#include <cstdint>
#include <vector>

#include "livo/lio/imu_propagator.hpp"
#include "livo/sensor_samples.hpp"

namespace livo::lio {

class Undistorter {
 public:
  /// segments: the propagation steps covering the sweep, in time order (at least one);
  /// (R_end, p_end): the body pose at end_utime (IMU clock); T_I_L: the extrinsic.
  Undistorter(const std::vector<ImuSegment>& segments, const Mat3& R_end, const Vec3& p_end, int64_t end_utime,
              const Pose3& T_I_L);

  /// Point p_L measured at `utime_ref + dt` (IMU clock; dt in seconds) in body frame I at the end.
  Vec3 toEnd(const Vec3& p_L, int64_t utime_ref, double dt) const {
    return toEndRelative(p_L, static_cast<double>(utime_ref - end_utime_) * 1e-6 + dt);
  }
  /// Same with the time relative to the end (t <= 0 inside the sweep).
  Vec3 toEndRelative(const Vec3& p_L, double t_rel_end) const;

  /// Undistorts a whole scan; `first_utime_imu` is scan.utime in the IMU clock, and every point was
  /// taken `time_shift` seconds after its stamp (the LiDAR's estimated time shift): it is moved
  /// along the motion from that instant to the end.
  void undistort(const LidarScan& scan, int64_t first_utime_imu, double time_shift, const std::vector<size_t>& indices,
                 std::vector<Vec3>* out_body) const;

 private:
  struct Seg {
    double t0;   // start, s relative to the end
    Mat3 R_L;    // R_k R_IL, with R_k = R_end^T R_k(world)
    Vec3 t_L;    // R_k t_IL
    Vec3 p;      // R_end^T (p_k - p_end)
    Vec3 v;      // R_end^T v_k
    Vec3 a;      // R_end^T acc_world_k
    Vec3 omega;  // R_k times the body rate over the step
  };
  /// Index of the segment holding time t (relative to the end).
  size_t segmentAt(double t) const;
  /// p_L measured at t, moved along segment `seg` into the body frame at the end.
  Vec3 moveToEnd(const Vec3& p_L, double t, size_t seg) const;

  std::vector<Seg> segs_;
  int64_t end_utime_;
};

/// Exp(w) v for the small angles of one IMU step (series to machine precision below 0.05 rad).
Vec3 expSmallTimes(const Vec3& w, const Vec3& v);

}  // namespace livo::lio
