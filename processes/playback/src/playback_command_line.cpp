#include "livo/playback/playback_command_line.hpp"

#include <sstream>
#include <stdexcept>

namespace livo::playback {

namespace {

/// "a,b,,c" -> a, b, c.
std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace

PlaybackOptions playbackOptionsFromCommandLine(const CommandLine& cli) {
  PlaybackOptions o;
  o.log = cli.get("LOG");
  o.speed = cli.getDouble("--speed");
  o.lockstep = cli.has("--lockstep");
  o.consumers = splitList(cli.get("--consumers"));
  o.source.channels = cli.get("--channels");
  o.source.start_s = cli.getDouble("--start");
  o.source.duration_s = cli.getDouble("--duration");
  for (const auto& f : splitList(cli.get("--faults"))) o.faults.push_back(parseFault(f));
  o.seed = static_cast<uint64_t>(cli.getInt("--seed"));
  o.out_log = cli.get("--out");
  o.progress_channel = cli.get("--progress-channel");
  o.clock_file = cli.get("--clock-file");
  o.stall_timeout_s = cli.getDouble("--stall-timeout");
  o.startup_timeout_s = cli.getDouble("--startup-timeout");
  o.loss_grace_s = cli.getDouble("--loss-grace");
  o.respawn = cli.has("--respawn");
  o.serial = cli.has("--serial");
  o.may_lag = splitList(cli.get("--lag"));
  o.max_lag_messages = static_cast<int>(cli.getInt("--max-lag"));
  if (o.max_lag_messages < 0) throw std::invalid_argument("--max-lag must be >= 0");
  const double max_lag_mb = cli.getDouble("--max-lag-mb");
  if (!(max_lag_mb >= 0.0)) throw std::invalid_argument("--max-lag-mb must be >= 0");
  o.max_lag_bytes = static_cast<int64_t>(max_lag_mb * 1048576.0);
  o.quiet = cli.has("--quiet");
  if (o.speed < 0) throw std::invalid_argument("--speed must be >= 0");
  return o;
}

}  // namespace livo::playback
