// PointCloud2 conversion without a bag: a spinning LiDAR's cloud with no per-point time field gets
// its times from the azimuth, in either turning direction and either point order.
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "livo/import/point_cloud2_conversion.hpp"

using namespace livo;
using namespace livo::import;

namespace {
constexpr uint8_t kUint16 = 4, kFloat32 = 7;  // sensor_msgs/PointField datatypes

// A 16-ring sweep of 360 columns, the first column at azimuth `start` rad, turning clockwise
// (azimuth falling) or not; points in firing order (column by column) or ring by ring (organised).
struct Sweep {
  std::vector<uint8_t> bytes;    // x y z (float32), ring (uint16), 2 bytes padding: 16 per point
  std::vector<double> fraction;  // of the sweep, per point
  RosPointCloud2 msg;
};
// `stagger_deg`: odd rings fire that far ahead in azimuth, even rings that far behind (OS1-64-like),
// at the same time as their column.
Sweep makeSweep(double start, bool clockwise, bool ring_major, double stagger_deg = 0.0) {
  Sweep s;
  constexpr int kRings = 16, kColumns = 360;
  auto add = [&](int ring, int col) {
    const double ahead = (ring % 2 ? 1.0 : -1.0) * stagger_deg * M_PI / 180.0;
    const double az = start + (clockwise ? -1.0 : 1.0) * (2.0 * M_PI * col / kColumns + ahead);
    const double el = (-15.0 + 2.0 * ring) * M_PI / 180.0;
    const double r = 10.0 + 0.1 * ring;
    const float xyz[3] = {float(r * std::cos(el) * std::cos(az)), float(r * std::cos(el) * std::sin(az)),
                          float(r * std::sin(el))};
    const uint16_t ring16 = static_cast<uint16_t>(ring);
    uint8_t point[16] = {};
    std::memcpy(point, xyz, sizeof xyz);
    std::memcpy(point + 12, &ring16, sizeof ring16);
    s.bytes.insert(s.bytes.end(), point, point + 16);
    s.fraction.push_back(double(col) / kColumns);
  };
  for (int a = 0; a < (ring_major ? kRings : kColumns); ++a)
    for (int b = 0; b < (ring_major ? kColumns : kRings); ++b) ring_major ? add(a, b) : add(b, a);
  s.msg.header.sec = 100;
  s.msg.height = ring_major ? kRings : 1;
  s.msg.width = ring_major ? kColumns : kRings * kColumns;
  s.msg.fields = {{"x", 0, kFloat32, 1}, {"y", 4, kFloat32, 1}, {"z", 8, kFloat32, 1}, {"ring", 12, kUint16, 1}};
  s.msg.point_step = 16;
  s.msg.row_step = 16 * s.msg.width;
  s.msg.data = s.bytes.data();
  s.msg.data_size = s.bytes.size();
  return s;
}
}  // namespace

TEST(PointCloud2Conversion, CloudsWithoutPointTimesGetThemFromTheAzimuth) {
  for (const bool clockwise : {true, false})
    for (const bool ring_major : {false, true}) {
      SCOPED_TRACE(std::string(clockwise ? "clockwise" : "counter-clockwise") +
                   (ring_major ? ", ring-major" : ", firing order"));
      const Sweep s = makeSweep(2.5, clockwise, ring_major);
      PointCloudConversionOptions o;
      o.sweep_duration = 0.1;
      const PointCloudConversion c = convertPointCloud2(s.msg, o, "test");
      ASSERT_EQ(c.cloud.num_points, 16 * 360);
      EXPECT_NE(c.layout.find(clockwise ? "from the azimuth, clockwise" : "from the azimuth, counter-clockwise"),
                std::string::npos)
          << c.layout;
      double worst = 0.0;
      for (int i = 0; i < c.cloud.num_points; ++i)
        worst = std::max(worst, std::abs(double(c.cloud.time_offset[i]) - 0.1 * s.fraction[i]));
      EXPECT_LT(worst, 1e-6);  // float rounding of the coordinates only
      EXPECT_LT(c.cloud.time_offset.back(), c.cloud.sweep_duration);
    }
}

// Beams staggered in azimuth put half of the first column behind the sweep's start: they belong at
// the start (off by the stagger's time only), never at the end of the sweep.
TEST(PointCloud2Conversion, StaggeredBeamsOfTheFirstColumnStayAtTheStart) {
  constexpr double kStaggerDeg = 1.5, kDuration = 0.1;
  for (const bool ring_major : {false, true}) {
    SCOPED_TRACE(ring_major ? "ring-major" : "firing order");
    const Sweep s = makeSweep(-1.0, true, ring_major, kStaggerDeg);
    PointCloudConversionOptions o;
    o.sweep_duration = kDuration;
    const PointCloudConversion c = convertPointCloud2(s.msg, o, "test");
    double worst = 0.0;
    for (int i = 0; i < c.cloud.num_points; ++i)
      worst = std::max(worst, std::abs(double(c.cloud.time_offset[i]) - kDuration * s.fraction[i]));
    EXPECT_LT(worst, kDuration * kStaggerDeg / 360.0 + 1e-6);
  }
}

TEST(PointCloud2Conversion, AzimuthTimesCanBeTurnedOff) {
  const Sweep s = makeSweep(0.0, true, false);
  PointCloudConversionOptions o;
  o.azimuth_times = false;
  const PointCloudConversion c = convertPointCloud2(s.msg, o, "test");
  for (float t : c.cloud.time_offset) ASSERT_EQ(t, 0.0f);
  EXPECT_NE(c.layout.find("(no per-point time)"), std::string::npos);
}
