// livo-octomap's node on memq://: scans in, OCTOMAP out at the publish period, files on finish,
// bad input refused.
#include <cmath>
#include <sstream>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <octomap/OcTree.h>

#include "livo/octomap_t.hpp"
#include "livo/registered_scan_t.hpp"
#include "octomap_node.hpp"
#include "temp_path.hpp"

using namespace livo;

namespace {
registered_scan_t wallScan(int64_t utime) {
  registered_scan_t s{};
  s.utime = utime;
  s.orientation[0] = 1.0;
  s.cloud.utime = utime - 100000;
  s.cloud.frame = "W";
  for (int i = -10; i <= 10; ++i)
    for (int j = -5; j <= 5; ++j) {
      s.cloud.x.push_back(2.05f);
      s.cloud.y.push_back(0.1f * i + 0.05f);
      s.cloud.z.push_back(0.1f * j + 0.05f);
    }
  s.cloud.num_points = static_cast<int32_t>(s.cloud.x.size());
  s.cloud.intensity.assign(s.cloud.x.size(), 0.f);
  s.cloud.time_offset.assign(s.cloud.x.size(), 0.f);
  s.cloud.ring.assign(s.cloud.x.size(), -1);
  return s;
}
}  // namespace

TEST(OctomapNode, PublishesTheTreeAndWritesFiles) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  octomap_export::OctomapNodeOptions options;
  options.publish_period_s = 0.5;
  options.write_period_s = 0;
  NodeOptions node_options;
  node_options.name = "octomap";
  node_options.quiet = true;
  node_options.health_period_s = 0;
  octomap_export::OctomapNode node(lcm, node_options, options, SensorRig{}, livo_test::tempPath("octo"));
  std::vector<octomap_t> received;
  lcm.subscribeFunction<octomap_t, std::vector<octomap_t>*>(
      "OCTOMAP", [](const lcm::ReceiveBuffer*, const std::string&, const octomap_t* m, std::vector<octomap_t>* out) {
        out->push_back(*m);
      },
      &received);
  for (int k = 0; k < 10; ++k) {
    const registered_scan_t s = wallScan(1000000 + 100000 * k);
    lcm.publish("REGISTERED_SCAN", &s);
  }
  registered_scan_t bad = wallScan(3000000);
  bad.orientation[0] = NAN;
  lcm.publish("REGISTERED_SCAN", &bad);
  registered_scan_t empty = wallScan(3100000);
  empty.cloud.num_points = 0;
  empty.cloud.x.clear();
  lcm.publish("REGISTERED_SCAN", &empty);
  while (lcm.handleTimeout(0) > 0) {
  }
  EXPECT_EQ(node.builder().scans(), 10);
  ASSERT_EQ(received.size(), 2u);  // at 1.0 s and 1.5 s
  std::istringstream in(std::string(received.back().data.begin(), received.back().data.end()));
  octomap::OcTree tree(0.1);
  ASSERT_TRUE(tree.readBinary(in));
  const octomap::OcTreeNode* n = tree.search(2.05, 0.05, 0.05);
  ASSERT_NE(n, nullptr);
  EXPECT_TRUE(tree.isNodeOccupied(n));
  node.finish();
  octomap::OcTree from_file(0.1);
  EXPECT_TRUE(from_file.readBinary(node.btPath()));
  std::unique_ptr<octomap::AbstractOcTree> ot(octomap::AbstractOcTree::read(node.otPath()));
  EXPECT_NE(ot, nullptr);
}
