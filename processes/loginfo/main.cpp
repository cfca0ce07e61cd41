// livo-loginfo LOG: what a log holds, per channel (like `rosbag info`).
#include <iostream>

#include "livo/command_line.hpp"
#include "log_summary.hpp"

int main(int argc, char** argv) {
  livo::CommandLine cli("livo-loginfo", "Prints duration and, per channel, type, count, rate and bytes of an LCM log.");
  cli.positional("LOG", "LCM log file (lcm-logger, livo-sim, livo-import)");
  cli.flag("--digest", "add a digest of each channel's payloads (equal digests: byte-identical streams)");
  if (!cli.parse(argc, argv)) return cli.exitCode();
  try {
    livo::printLogSummary(livo::summarizeLog(cli.get("LOG")), std::cout, cli.has("--digest"));
  } catch (const std::exception& e) {
    std::cerr << "livo-loginfo: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
