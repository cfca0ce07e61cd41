// livo-loginfo LOG: what a log holds, per channel (like `rosbag info`).
#include <iostream>

#include "livo/command_line.hpp"
#include "livo/loginfo/log_summary.hpp"

int main(int argc, char** argv) {
  livo::CommandLine cli("livo-loginfo", "Prints duration and, per channel, type, count, rate and bytes of an LCM log.");
  cli.positional("LOG", "LCM log file (lcm-logger, livo-sim, livo-import)");
  cli.flag("--digest", "add a digest of each channel's payloads (equal digests: byte-identical streams)");
  cli.flag("--nonfinite", "add the number of messages holding a NaN or an infinity; exit 3 if there is any");
  if (!cli.parse(argc, argv)) return cli.exitCode();
  try {
    const livo::loginfo::LogSummary summary = livo::loginfo::summarizeLog(cli.get("LOG"));
    livo::loginfo::printLogSummary(summary, std::cout, cli.has("--digest"), cli.has("--nonfinite"));
    if (cli.has("--nonfinite")) {
      int64_t bad = 0;
      for (const auto& [name, c] : summary.channels) bad += c.non_finite_messages;
      if (bad > 0) {
        std::cerr << "livo-loginfo: " << bad << " messages hold a NaN or an infinity\n";
        return 3;
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "livo-loginfo: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
