// KITTI OXTS (RT3003 GPS/IMU) packets: one text line of 30 numbers per file
// (lat lon alt roll pitch yaw vn ve vf vl vu ax ay az af al au wx wy wz wf wl wu
//  pos_accuracy vel_accuracy navstat numsats posmode velmode orimode).
// The IMU sample uses ax ay az / wx wy wz: the packet's own body frame (x forward, y left, z up,
// fixed to the vehicle; specific force, gravity included). af al au / wf wl wu are the same
// quantities in the gravity-levelled vehicle frame and are not used.
// Poses use the KITTI devkit's Mercator projection with the scale of the first fix's latitude:
//   x = s * R * lon,  y = s * R * ln(tan(pi/4 + lat/2)),  z = alt,   s = cos(lat0), R = 6378137 m
// (x east, y north, z up), then shifted so the first fix is the origin; orientation
// R = Rz(yaw) Ry(pitch) Rx(roll) maps the packet frame into that local frame.
#pragma once

#include <array>
#include <string>

#include "livo/so3.hpp"

namespace livo::import {

struct OxtsPacket {
  std::array<double, 30> v{};
  double lat() const { return v[0]; }
  double lon() const { return v[1]; }
  double alt() const { return v[2]; }
  double roll() const { return v[3]; }
  double pitch() const { return v[4]; }
  double yaw() const { return v[5]; }
  Vec3 accel() const { return Vec3(v[11], v[12], v[13]); }  // ax ay az
  Vec3 gyro() const { return Vec3(v[17], v[18], v[19]); }   // wx wy wz
};

/// Throws std::runtime_error naming the file and the field that is missing or not a number.
OxtsPacket readOxtsFile(const std::string& path);

class OxtsLocalFrame {
 public:
  /// The first packet fixes the Mercator scale and the origin.
  explicit OxtsLocalFrame(const OxtsPacket& first);
  /// Pose of the packet frame in the local frame W.
  Pose3 pose(const OxtsPacket& p) const;

 private:
  double scale_;
  Vec3 origin_;
  Vec3 mercator(const OxtsPacket& p) const;
};

}  // namespace livo::import
