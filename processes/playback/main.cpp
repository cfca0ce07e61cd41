// livo-playback LOG: real-time or lockstep replay with optional fault injection.
#include <iostream>

#include <lcm/lcm-cpp.hpp>

#include "livo/command_line.hpp"
#include "livo/node.hpp"
#include "livo/playback/playback.hpp"
#include "livo/playback/playback_command_line.hpp"

namespace {

livo::CommandLine playbackCommandLine() {
  livo::CommandLine cli("livo-playback",
                        "Replays an LCM log onto the bus: real time, faster, or in lockstep with the pipeline.");
  cli.positional("LOG", "LCM log to replay")
      .option("--speed", "X", "real-time factor; 0 = as fast as possible (ignored with --lockstep)", "1.0")
      .flag("--lockstep", "publish each message only after every consumer reported it handled the previous one")
      .option("--consumers", "A,B,...",
              "node names to wait for (their --name): at the start, and with --lockstep after every message")
      .option("--channels", "REGEX", "replay only channels matching this regular expression", ".*")
      .option("--start", "S", "skip the first S seconds of the log", "0")
      .option("--duration", "S", "replay only S seconds (0: to the end)", "0")
      .option("--faults", "F,F,...",
              "faults to inject: drop:CH:FRAC duplicate:CH:FRAC delay:CH:FRAC:S reorder:CH:FRAC corrupt:CH:FRAC "
              "nan:CH:FRAC jump:CH:AT_S:JUMP_S cut:CH:FROM_S:TO_S")
      .option("--seed", "N", "seed of the fault injector", "1")
      .option("--out", "LOG", "write the (faulted) stream to this log instead of publishing")
      .option(
          "--clock-file", "FILE",
          "keep the log seconds replayed so far in FILE (rewritten every 20 ms; for supervisors that act at log times)")
      .option("--progress-channel", "CH", "channel of the nodes' PROGRESS messages", "PROGRESS")
      .option("--stall-timeout", "S",
              "lockstep: give up when a consumer is behind on a channel and its count has not moved for S seconds",
              "30")
      .option("--loss-grace", "S",
              "lockstep: an idle consumer still lacking a message published S seconds ago lost it on the bus "
              "(reported, then not waited for)",
              "3")
      .flag("--serial",
            "lockstep: wait for every consumer after every message, ignoring their quiet promises and --lag "
            "(the reference the default must equal)")
      .option("--lag", "A,B,...",
              "lockstep: consumers that may fall behind the rest (their outputs feed only recorders; checked)")
      .option("--max-lag", "N", "lockstep: how many messages a --lag consumer may be behind", "16")
      .option("--max-lag-mb", "MB", "lockstep: and how many megabytes (at each channel's mean message size)", "16")
      .flag("--respawn", "lockstep: consumers may exit and be restarted by a supervisor; not waited for while away")
      .option("--startup-timeout", "S", "lockstep: give up when a consumer has not reported within S seconds", "30")
      .option("--lcm-url", "URL", "LCM URL (default: $LCM_DEFAULT_URL)")
      .flag("--quiet", "no progress output");
  return cli;
}

void printSummary(const livo::playback::PlaybackResult& r) {
  std::cerr << "[playback] " << r.published << " messages, " << r.log_seconds << " s of log in " << r.wall_seconds
            << " s" << (r.lost > 0 ? ", " + std::to_string(r.lost) + " lost on the bus" : std::string())
            << (r.restarts > 0 ? ", " + std::to_string(r.restarts) + " consumer restarts" : std::string())
            << (r.not_waited > 0
                    ? "; " + std::to_string(r.not_waited) +
                          " went on before the whole pipeline had handled them (quiet promises, lagging consumers)"
                    : std::string())
            << std::endl;
  std::cerr << "[playback] CPU " << livo::cpuSeconds() << " s (user + system)" << std::endl;
  if (!r.waits.empty()) {
    const auto lines = livo::playback::describeWaits(r.waits);
    if (!lines.empty()) std::cerr << "[playback] lockstep waits, longest first (whose report ended them):\n";
    for (const auto& l : lines) std::cerr << "[playback]   " << l << "\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  livo::CommandLine cli = playbackCommandLine();
  if (!cli.parse(argc, argv)) return cli.exitCode();
  try {
    const livo::playback::PlaybackOptions o = livo::playback::playbackOptionsFromCommandLine(cli);
    if (!o.quiet)
      for (const auto& f : o.faults) std::cerr << "[playback] fault: " << livo::playback::describe(f) << "\n";
    livo::keepLargeBlocksOnHeap();
    std::unique_ptr<lcm::LCM> lcm;
    if (o.out_log.empty()) lcm = livo::makeLcm(cli.get("--lcm-url"));
    livo::installSignalHandlers();
    const livo::playback::PlaybackResult r = livo::playback::runPlayback(o, lcm.get());
    if (!o.quiet) printSummary(r);
    if (!r.error.empty()) {
      std::cerr << "livo-playback: " << r.error << std::endl;
      return 1;
    }
  } catch (const std::exception& e) {
    std::cerr << "livo-playback: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
