#include "livo/import/kitti_velodyne.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "livo/import/file_utils.hpp"

namespace livo::import {

KittiScan readKittiBin(const std::string& path, KittiPointFields fields, KittiPointFields* used) {
  const std::vector<uint8_t> bytes = readFileBytes(path);
  const size_t n = bytes.size();
  if (fields == KittiPointFields::kAuto) {
    const bool by16 = n % 16 == 0, by12 = n % 12 == 0;
    if (by16 && !by12) {
      fields = KittiPointFields::kXyzi;
    } else if (by12 && !by16) {
      fields = KittiPointFields::kXyz;
    } else if (by16 && by12) {
      bool reflectance = true;
      for (size_t off = 12; off + 4 <= n && reflectance; off += 16) {
        float r;
        std::memcpy(&r, bytes.data() + off, 4);
        reflectance = r >= 0.0f && r <= 1.0f;
      }
      fields = reflectance ? KittiPointFields::kXyzi : KittiPointFields::kXyz;
    }
  }
  const size_t stride = fields == KittiPointFields::kXyzi ? 16 : 12;
  if (fields == KittiPointFields::kAuto || n % stride != 0)
    throw std::runtime_error(
        path + ": " + std::to_string(n) + " bytes is not a whole number of " +
        (fields == KittiPointFields::kAuto ? std::string("12- or 16-byte") : std::to_string(stride) + "-byte") +
        " points (truncated?)");
  if (used) *used = fields;
  KittiScan s;
  const size_t count = n / stride;
  s.x.resize(count), s.y.resize(count), s.z.resize(count), s.intensity.assign(count, 0.0f);
  for (size_t i = 0; i < count; ++i) {
    const uint8_t* p = bytes.data() + i * stride;
    std::memcpy(&s.x[i], p, 4);
    std::memcpy(&s.y[i], p + 4, 4);
    std::memcpy(&s.z[i], p + 8, 4);
    if (stride == 16) std::memcpy(&s.intensity[i], p + 12, 4);
  }
  return s;
}

KittiScan readKittiText(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  KittiScan s;
  std::string line;
  int ln = 0;
  while (std::getline(in, line)) {
    ++ln;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream ss(line);
    float v[4] = {0, 0, 0, 0};
    int got = 0;
    while (got < 4 && ss >> v[got]) ++got;
    if (got < 3) throw std::runtime_error(path + ":" + std::to_string(ln) + ": expected 'x y z [r]'");
    s.x.push_back(v[0]), s.y.push_back(v[1]), s.z.push_back(v[2]), s.intensity.push_back(v[3]);
  }
  return s;
}

int hdl64RingFromElevation(double elevation_rad) {
  const double deg = elevation_rad * 180.0 / M_PI;
  int from_top;
  if (deg > -8.58)  // between the upper block's last beam (-8.33) and the lower's first (-8.83)
    from_top = std::clamp(static_cast<int>(std::lround((2.0 - deg) * 3.0)), 0, 31);
  else
    from_top = 32 + std::clamp(static_cast<int>(std::lround((-8.83 - deg) * 2.0)), 0, 31);
  return 63 - from_top;
}

double kittiTimeOffset(double x, double y, double sweep_duration) {
  const double fraction = (M_PI - std::atan2(y, x)) / (2.0 * M_PI);  // atan2 in (-pi, pi]: [0, 1)
  return std::min(fraction, std::nextafter(1.0, 0.0)) * sweep_duration;
}

point_cloud_t kittiScanToCloud(const KittiScan& s, int64_t start_utime, double sweep_duration, int64_t* dropped) {
  point_cloud_t c;
  c.utime = start_utime;
  c.frame = "L";
  c.pattern = point_cloud_t::PATTERN_SPINNING;
  c.num_rings = 64;
  c.sweep_duration = static_cast<float>(sweep_duration);
  int64_t bad = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    const float x = s.x[i], y = s.y[i], z = s.z[i];
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
      ++bad;
      continue;
    }
    c.x.push_back(x), c.y.push_back(y), c.z.push_back(z), c.intensity.push_back(s.intensity[i]);
    const float t = static_cast<float>(kittiTimeOffset(x, y, sweep_duration));
    c.time_offset.push_back(std::min(t, std::nextafter(c.sweep_duration, 0.0f)));
    c.ring.push_back(
        static_cast<int16_t>(hdl64RingFromElevation(std::atan2(double(z), std::hypot(double(x), double(y))))));
  }
  c.num_points = static_cast<int32_t>(c.x.size());
  if (dropped) *dropped = bad;
  return c;
}

}  // namespace livo::import
