// livo-sensor-watch: warns when a live sensor goes silent (scripts/run_live.sh runs it).
#include <chrono>
#include <fstream>
#include <iostream>
#include <sstream>

#include <lcm/lcm-cpp.hpp>

#include "livo/command_line.hpp"
#include "livo/config.hpp"
#include "livo/message_registry.hpp"
#include "livo/node.hpp"
#include "livo/sensor_rig.hpp"
#include "livo/sensor_watch/gap_watch.hpp"
#include "livo/text_format.hpp"

namespace {

using Clock = std::chrono::steady_clock;

// The IMU and LiDAR channels of the config's rig, or --channels.
std::vector<std::string> watchedChannels(const livo::CommandLine& cli) {
  std::vector<std::string> out;
  if (cli.has("--channels")) {
    std::stringstream ss(cli.get("--channels"));
    for (std::string c; std::getline(ss, c, ',');)
      if (!c.empty()) out.push_back(c);
    return out;
  }
  if (!cli.has("--config")) throw std::invalid_argument("--config or --channels is required");
  const livo::SensorRig rig = livo::readSensorRig(livo::Config::load(cli.get("--config")).section("rig"));
  return {rig.channels.imu, rig.channels.lidar};
}

class Watcher {
 public:
  Watcher(livo::sensor_watch::GapWatch& watch, std::ofstream& out) : watch_(watch), out_(out) {}
  double now() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }
  void onMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    int64_t utime = 0;
    if (!livo::messageUtime(rbuf->data, static_cast<int>(rbuf->data_size), &utime)) utime = 0;
    if (auto gap = watch_.arrived(channel, now(), utime)) {
      std::cerr << "livo-sensor-watch: warning: " << channel << " back after " << livo::formatFixed(gap->length(), 2)
                << " s without a message (" << livo::formatFixed(gap->from_s, 2) << " .. "
                << livo::formatFixed(gap->to_s, 2) << " s)" << std::endl;
      livo::sensor_watch::writeGapLine(out_, *gap);
      out_.flush();
    }
  }
  void checkSilence() {
    for (const auto& gap : watch_.newlySilent(now()))
      std::cerr << "livo-sensor-watch: warning: no " << gap.channel << " for " << livo::formatFixed(gap.length(), 1)
                << " s (the last at " << livo::formatFixed(gap.from_s, 2) << " s)" << std::endl;
  }
  void finish() {
    for (const auto& gap : watch_.finish(now())) {
      if (gap.never)
        std::cerr << "livo-sensor-watch: warning: no message on " << gap.channel << " in "
                  << livo::formatFixed(gap.length(), 1) << " s" << std::endl;
      else
        std::cerr << "livo-sensor-watch: warning: " << gap.channel << " still silent at the end, for "
                  << livo::formatFixed(gap.length(), 2) << " s" << std::endl;
      livo::sensor_watch::writeGapLine(out_, gap);
    }
    out_.flush();
  }

 private:
  livo::sensor_watch::GapWatch& watch_;
  std::ofstream& out_;
  Clock::time_point start_ = Clock::now();
};

}  // namespace

int main(int argc, char** argv) {
  livo::CommandLine cli("livo-sensor-watch",
                        "Warns on stderr when a watched channel carries no message for --gap seconds (wall clock) "
                        "and writes each such gap to --out; stops on SIGINT or SIGTERM.");
  cli.option("--config", "FILE", "pipeline config: watches its rig's IMU and LiDAR channels")
      .option("--channels", "A,B,...", "channels to watch instead of the rig's IMU and LiDAR")
      .option("--gap", "S", "silence that makes a gap, seconds", "1.0")
      .option("--out", "FILE", "gaps file (tab-separated, one gap a line)")
      .option("--lcm-url", "URL", "LCM URL (default: $LCM_DEFAULT_URL)");
  if (!cli.parse(argc, argv)) return cli.exitCode();
  if (!cli.has("--out")) {
    std::cerr << "livo-sensor-watch: --out is required\n" << cli.usage();
    return 2;
  }
  try {
    const std::vector<std::string> channels = watchedChannels(cli);
    livo::sensor_watch::GapWatch watch(channels, cli.getDouble("--gap"));
    std::ofstream out(cli.get("--out"));
    if (!out) throw std::runtime_error(cli.get("--out") + ": cannot write");
    out << "# channel\tfrom_s\tto_s\tlength_s\tend\tstamp_before_s\tstamp_after_s\n";
    auto lcm = livo::makeLcm(cli.get("--lcm-url"));
    livo::installSignalHandlers();
    Watcher watcher(watch, out);
    for (const auto& c : channels) lcm->subscribe(c, &Watcher::onMessage, &watcher);
    std::string joined;
    for (const auto& c : channels) joined += (joined.empty() ? "" : ", ") + c;
    std::cerr << "livo-sensor-watch: watching " << joined << " (a gap: " << cli.get("--gap") << " s without a message)"
              << std::endl;
    while (!livo::shutdownRequested()) {
      // a signal interrupts the wait (-1): the loop ends on the flag it set
      if (lcm->handleTimeout(100) < 0 && !livo::shutdownRequested())
        throw std::runtime_error("the LCM provider failed");
      watcher.checkSilence();
    }
    watcher.finish();
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "livo-sensor-watch: " << e.what() << std::endl;
    return 1;
  }
}
