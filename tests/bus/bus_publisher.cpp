// Publishes bus_test::kMessages point clouds of ~1 MB at 10 Hz once the subscriber is ready.
#include <chrono>
#include <fstream>
#include <iostream>
#include <thread>

#include "bus_payload.hpp"
#include "livo/node.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: test-bus-publisher READY_FILE\n";
    return 2;
  }
  auto lcm = livo::makeLcm("");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (!std::ifstream(argv[1]).good()) {
    if (std::chrono::steady_clock::now() > deadline) {
      std::cerr << "test-bus-publisher: subscriber never became ready\n";
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  auto next = std::chrono::steady_clock::now();
  for (int64_t seq = 0; seq < bus_test::kMessages; ++seq) {
    const livo::point_cloud_t c = bus_test::makeCloud(seq);
    std::this_thread::sleep_until(next);
    if (lcm->publish("BUS_TEST", &c) != 0) {
      std::cerr << "test-bus-publisher: publish failed at " << seq << "\n";
      return 1;
    }
    next += std::chrono::milliseconds(100);
  }
  std::cout << "published " << bus_test::kMessages << " clouds of " << bus_test::makeCloud(0).getEncodedSize()
            << " bytes\n";
  return 0;
}
