// ros_bridge_test.sh's recorder of the LCM bus in real time: lcm-logger without its losses.
// lcm-logger keeps LCM's default subscription queue (30 unhandled messages; LCM's receive thread
// drops what comes beyond it), so at the bridge's paced bursts (one message per ms) a handler
// thread starved for 30 ms on a loaded machine loses messages (measured: 1594 of 1601 IMU samples
// recorded at load average 7). This recorder's subscription has no queue limit: LCM's receive
// thread keeps reading the socket and holds every message until the handler writes it, so only
// the kernel's socket buffer (recv_buf_size in scripts/private_bus.sh's URL) bounds a stall.
// On SIGINT/SIGTERM it writes what is still queued (until the bus has been quiet for 0.5 s) and
// prints the count per channel.
//
//   livo_ros_bridge_bus_recorder CHANNEL_REGEX OUT.lcmlog      (LCM_DEFAULT_URL: the bus)
#include <csignal>
#include <cstdio>
#include <iostream>
#include <map>
#include <string>

#include <lcm/lcm-cpp.hpp>

namespace {
volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) { g_stop = 1; }

struct Writer {
  lcm::LogFile* log;
  std::map<std::string, long> counts;
  bool failed = false;
  void onMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    lcm::LogEvent ev;
    ev.timestamp = rbuf->recv_utime;
    ev.channel = channel;
    ev.datalen = static_cast<int32_t>(rbuf->data_size);
    ev.data = rbuf->data;
    if (log->writeEvent(&ev) != 0) failed = true;
    ++counts[channel];
  }
};
}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: livo_ros_bridge_bus_recorder CHANNEL_REGEX OUT.lcmlog\n";
    return 2;
  }
  lcm::LogFile log(argv[2], "w");
  if (!log.good()) {
    std::cerr << argv[2] << ": cannot write\n";
    return 1;
  }
  lcm::LCM lcm;
  if (!lcm.good()) {
    std::cerr << "cannot open the LCM bus\n";
    return 1;
  }
  Writer writer{&log, {}};
  lcm::Subscription* sub = lcm.subscribe(argv[1], &Writer::onMessage, &writer);
  sub->setQueueCapacity(0);  // no limit: nothing the bus delivered is dropped while we are descheduled
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  while (!g_stop) lcm.handleTimeout(100);
  while (lcm.handleTimeout(500) > 0) {
  }
  std::fflush(log.getFilePtr());
  std::cerr << "recorded:";
  for (const auto& [channel, n] : writer.counts) std::cerr << " " << channel << " " << n;
  std::cerr << "\n";
  if (writer.failed) {
    std::cerr << argv[2] << ": write failed (disk full?)\n";
    return 1;
  }
  return 0;
}
