// test-fake-lio --config FILE --name NAME: a stand-in for livo-lio in the runner tests. On every
// LIDAR scan it publishes as ODOMETRY the newest GROUND_TRUTH pose at or before the scan, moved by
// a known wobble (1 cm along x times sin(scan index)), and every 10th scan a KEYFRAME.
// FAKE_LIO_CRASH_AFTER=N makes it abort after N scans (a crashing process).
#include <cmath>
#include <cstdlib>
#include <iostream>

#include "livo/command_line.hpp"
#include "livo/keyframe_t.hpp"
#include "livo/node.hpp"
#include "livo/odometry_t.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/pose_t.hpp"

int main(int argc, char** argv) {
  livo::CommandLine cli("test-fake-lio", "ODOMETRY from GROUND_TRUTH, for runner tests");
  cli.option("--config", "FILE", "ignored").option("--name", "NAME", "node name", "lio");
  if (!cli.parse(argc, argv)) return cli.exitCode();
  const char* crash = std::getenv("FAKE_LIO_CRASH_AFTER");
  const long crash_after = crash ? std::atol(crash) : -1;
  auto lcm = livo::makeLcm("");
  livo::NodeOptions o;
  o.name = cli.get("--name");
  livo::Node node(*lcm, o);
  node.declareOutput("ODOMETRY");
  node.declareOutput("KEYFRAME");
  livo::pose_t latest{};
  bool have_gt = false;
  long scans = 0;
  node.subscribe<livo::pose_t>("GROUND_TRUTH", [&](const livo::pose_t& p) {
    latest = p;
    have_gt = true;
  });
  node.subscribe<livo::point_cloud_t>("LIDAR", [&](const livo::point_cloud_t& c) {
    if (!have_gt) return;
    livo::odometry_t odo{};
    odo.utime = c.utime;
    odo.parent_frame = "W";
    odo.child_frame = "I";
    for (int i = 0; i < 3; ++i) odo.position[i] = latest.position[i];
    odo.position[0] += 0.01 * std::sin(static_cast<double>(scans));
    for (int i = 0; i < 4; ++i) odo.orientation[i] = latest.orientation[i];
    node.publish("ODOMETRY", odo);
    if (scans % 10 == 0) {
      livo::keyframe_t k{};
      k.id = scans / 10;
      k.utime = c.utime;
      for (int i = 0; i < 3; ++i) k.position[i] = odo.position[i];
      for (int i = 0; i < 4; ++i) k.orientation[i] = odo.orientation[i];
      k.cloud.frame = "I";
      node.publish("KEYFRAME", k);
    }
    if (++scans == crash_after) {
      std::cerr << "fake lio: crashing on purpose after " << scans << " scans" << std::endl;
      std::abort();
    }
  });
  return livo::spin(*lcm, node);
}
