#include <gtest/gtest.h>

#include <cmath>

#include "livo/message_checks.hpp"

using namespace livo;

namespace {
registered_scan_t goodScan() {
  registered_scan_t m{};
  m.orientation[0] = 1.0;
  m.cloud.frame = "W";
  m.cloud.num_points = 2;
  m.cloud.x = {1, 2};
  m.cloud.y = {1, 2};
  m.cloud.z = {1, 2};
  m.cloud.intensity = {0, 0};
  m.cloud.time_offset = {0, 0.05f};
  m.cloud.ring = {0, 1};
  return m;
}
}  // namespace

TEST(MessageChecks, RegisteredScanProblems) {
  EXPECT_EQ(registeredScanProblem(goodScan()), "");
  registered_scan_t m = goodScan();
  m.cloud.num_points = 0;
  EXPECT_EQ(registeredScanProblem(m), "empty cloud");
  m = goodScan();
  m.cloud.y.pop_back();  // a short y array would be read past its end
  EXPECT_EQ(registeredScanProblem(m), "cloud arrays disagree with num_points");
  m = goodScan();
  m.position[1] = std::nan("");
  EXPECT_EQ(registeredScanProblem(m), "pose is not finite");
  m = goodScan();
  m.cloud.frame = "L";
  EXPECT_EQ(registeredScanProblem(m), "cloud frame is 'L', expected W");
}
