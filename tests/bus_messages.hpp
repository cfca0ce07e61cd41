// Encoded LCM messages in a test's own order, for feeding a node on the in-process memq://
// provider: each carries the key it arrives by (a sweep at its end, an IMU sample at its stamp,
// or whatever order a test wants to try), and publishAll hands them over one by one, letting every
// node handle each before the next, as the lockstep replay does.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

namespace livo_test {

struct Message {
  int64_t order_key;
  std::string channel;
  std::vector<uint8_t> bytes;
};

template <class M>
Message encode(int64_t key, const std::string& channel, const M& m) {
  Message out{key, channel, std::vector<uint8_t>(static_cast<size_t>(m.getEncodedSize()))};
  m.encode(out.bytes.data(), 0, static_cast<int>(out.bytes.size()));
  return out;
}

/// Sorted by arrival key; messages with equal keys keep their order.
inline void sortByArrival(std::vector<Message>* messages) {
  std::stable_sort(messages->begin(), messages->end(),
                   [](const Message& a, const Message& b) { return a.order_key < b.order_key; });
}

/// Every message handled by everything subscribed before the next is published.
inline void drain(lcm::LCM& lcm) {
  while (lcm.handleTimeout(0) > 0) {
  }
}

inline void publishAll(lcm::LCM& lcm, const std::vector<Message>& messages) {
  for (const Message& m : messages) {
    lcm.publish(m.channel, m.bytes.data(), static_cast<unsigned>(m.bytes.size()));
    drain(lcm);
  }
}

}  // namespace livo_test
