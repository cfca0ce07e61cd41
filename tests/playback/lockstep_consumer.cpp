// test-lockstep-consumer NAME MODE [DIE_AFTER]
//   stage1: takes IMU and LIDAR, sleeps a random 0-2 ms (wall clock) per message, and publishes
//           STAGE1 for every IMU message.
//   stage2: takes IMU and STAGE1; for every IMU message publishes STAGE2 holding how many STAGE1
//           messages stamped before it it has seen. Under lockstep that is always exactly the IMU
//           index, so two replays give identical STAGE2; free-running it depends on timing.
//           It counts by stamp, as every node of the pipeline acts (design.md, "Determinism"),
//           not by arrival: STAGE1 for IMU i may reach it before IMU i itself. Lockstep holds
//           IMU i back until the node messages published before it are handled, but nothing
//           orders two senders' datagrams at a third socket: a (v)CPU stalled between delivering
//           IMU i to stage1's socket and to stage2's lets stage1's answer overtake it. Counting
//           by arrival, the two replays' STAGE2 once differed in CI on a loaded machine.
//   DIE_AFTER N: after N messages, "crash" (_exit without a final PROGRESS) or "exit" (clean).
#include <unistd.h>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <random>
#include <set>
#include <string>
#include <thread>

#include "livo/imu_t.hpp"
#include "livo/node.hpp"
#include "livo/pose_t.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: test-lockstep-consumer stage1|stage2 [crash|exit N]\n";
    return 2;
  }
  const std::string name = argv[1];
  const std::string die_mode = argc >= 4 ? argv[2] : "";
  const long die_after = argc >= 4 ? std::atol(argv[3]) : -1;
  auto lcm = livo::makeLcm("");
  livo::NodeOptions opts;
  opts.name = name;
  opts.quiet = true;
  livo::Node node(*lcm, opts);
  std::mt19937 jitter(std::random_device{}());
  long handled = 0;
  auto afterMessage = [&] {
    std::this_thread::sleep_for(std::chrono::microseconds(jitter() % 2000));
    if (++handled == die_after) {
      if (die_mode == "crash") _exit(3);
      livo::requestShutdown();
    }
  };
  int64_t stage1_seen = 0;
  std::multiset<int64_t> stage1_stamps;  // stage2: the STAGE1 messages received, not yet counted
  if (name == "stage1") {
    node.declareOutput("STAGE1");
    node.subscribe<livo::imu_t>("IMU", [&](const livo::imu_t& m) {
      livo::pose_t p{};
      p.utime = m.utime;
      p.parent_frame = "W";
      p.child_frame = "stage1";
      p.orientation[0] = 1;
      node.publish("STAGE1", p);
      afterMessage();
    });
    node.subscribeRaw("LIDAR", [&](const void*, int) { afterMessage(); });
  } else {
    node.declareOutput("STAGE2");
    node.subscribe<livo::pose_t>("STAGE1", [&](const livo::pose_t& m) { stage1_stamps.insert(m.utime); });
    node.subscribe<livo::imu_t>("IMU", [&](const livo::imu_t& m) {
      livo::pose_t p{};
      p.utime = m.utime;
      p.parent_frame = "W";
      p.child_frame = "stage2";
      while (!stage1_stamps.empty() && *stage1_stamps.begin() < m.utime) {
        stage1_stamps.erase(stage1_stamps.begin());
        ++stage1_seen;
      }
      p.position[0] = static_cast<double>(stage1_seen);
      p.orientation[0] = 1;
      node.publish("STAGE2", p);
      afterMessage();
    });
  }
  return livo::spin(*lcm, node);
}
