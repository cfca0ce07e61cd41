// Receives the publisher's clouds through the node framework and checks every one arrived intact.
#include <chrono>
#include <fstream>
#include <iostream>
#include <set>

#include "bus_payload.hpp"
#include "livo/node.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: test-bus-subscriber READY_FILE\n";
    return 2;
  }
  auto lcm = livo::makeLcm("");
  livo::NodeOptions opts;
  opts.name = "bus_subscriber";
  livo::Node node(*lcm, opts);
  std::set<int64_t> received;
  int corrupt = 0;
  node.subscribe<livo::point_cloud_t>("BUS_TEST", [&](const livo::point_cloud_t& c) {
    if (!bus_test::intact(c)) ++corrupt;
    received.insert(c.utime);
  });
  std::ofstream(argv[1]) << "ready\n";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  livo::spin(*lcm, node, {}, [&] {
    return static_cast<int>(received.size()) == bus_test::kMessages || std::chrono::steady_clock::now() > deadline;
  });
  const int lost = bus_test::kMessages - static_cast<int>(received.size());
  std::cout << "received " << received.size() << "/" << bus_test::kMessages << ", lost " << lost << ", corrupt "
            << corrupt << ", decode failures " << node.decodeFailures() << "\n";
  return (lost == 0 && corrupt == 0 && node.decodeFailures() == 0) ? 0 : 1;
}
