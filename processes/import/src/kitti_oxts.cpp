#include "livo/import/kitti_oxts.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace livo::import {

namespace {
const char* const kOxtsFields[30] = {
    "lat", "lon", "alt", "roll",         "pitch",        "yaw",     "vn",      "ve",      "vf",      "vl",
    "vu",  "ax",  "ay",  "az",           "af",           "al",      "au",      "wx",      "wy",      "wz",
    "wf",  "wl",  "wu",  "pos_accuracy", "vel_accuracy", "navstat", "numsats", "posmode", "velmode", "orimode"};
constexpr double kEarthRadius = 6378137.0;
}  // namespace

OxtsPacket readOxtsFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::string line;
  std::getline(in, line);
  std::istringstream ss(line);
  OxtsPacket p;
  for (int i = 0; i < 30; ++i) {
    std::string tok;
    if (!(ss >> tok))
      throw std::runtime_error(path + ": field '" + kOxtsFields[i] + "' (" + std::to_string(i + 1) + " of 30) missing");
    try {
      size_t used = 0;
      p.v[i] = std::stod(tok, &used);
      if (used != tok.size()) throw std::invalid_argument(tok);
    } catch (const std::exception&) {
      throw std::runtime_error(path + ": field '" + kOxtsFields[i] + "': '" + tok + "' is not a number");
    }
  }
  return p;
}

OxtsLocalFrame::OxtsLocalFrame(const OxtsPacket& first) : scale_(std::cos(first.lat() * M_PI / 180.0)) {
  origin_ = mercator(first);
}

Vec3 OxtsLocalFrame::mercator(const OxtsPacket& p) const {
  const double x = scale_ * kEarthRadius * p.lon() * M_PI / 180.0;
  const double y = scale_ * kEarthRadius * std::log(std::tan(M_PI * (90.0 + p.lat()) / 360.0));
  return Vec3(x, y, p.alt());
}

Pose3 OxtsLocalFrame::pose(const OxtsPacket& p) const {
  Pose3 T = Pose3::Identity();
  T.linear() = (Eigen::AngleAxisd(p.yaw(), Vec3::UnitZ()) * Eigen::AngleAxisd(p.pitch(), Vec3::UnitY()) *
                Eigen::AngleAxisd(p.roll(), Vec3::UnitX()))
                   .toRotationMatrix();
  T.translation() = mercator(p) - origin_;
  return T;
}

}  // namespace livo::import
