// livo-record --out LOG --channels A,B,...: records channels as a lockstep participant.
#include <cstdlib>
#include <iostream>
#include <memory>
#include <sstream>

#include "livo/command_line.hpp"
#include "livo/record/recorder.hpp"

namespace {
// LIVO_RECORD_ARRIVALS: --arrivals from the environment (scripts/run_pipeline.sh in real time)
std::string arrivalsDefault() {
  const char* v = std::getenv("LIVO_RECORD_ARRIVALS");
  return v ? v : "";
}
}  // namespace

int main(int argc, char** argv) {
  livo::CommandLine cli(
      "livo-record",
      "Records the named channels into an LCM log, reporting PROGRESS so lockstep playback waits for it.");
  cli.option("--out", "LOG", "log to write")
      .option("--channels", "A,B,...", "channels to record (names, not patterns)")
      .option("--name", "NAME", "node name on the bus", "record")
      .option("--lcm-url", "URL", "LCM URL (default: $LCM_DEFAULT_URL)")
      .option("--arrivals", "FILE",
              "also write when each message on the bus (but PROGRESS) arrived, wall clock, to FILE: real-time "
              "latency (livo-report extract --arrivals); the log is unchanged",
              arrivalsDefault());
  if (!cli.parse(argc, argv)) return cli.exitCode();
  if (!cli.has("--out") || !cli.has("--channels")) {
    std::cerr << "livo-record: --out and --channels are required\n" << cli.usage();
    return 2;
  }
  try {
    std::vector<std::string> channels;
    std::stringstream ss(cli.get("--channels"));
    for (std::string c; std::getline(ss, c, ',');)
      if (!c.empty()) channels.push_back(c);
    auto lcm = livo::makeLcm(cli.get("--lcm-url"));
    livo::NodeOptions o;
    o.name = cli.get("--name");
    o.quiet = true;
    livo::Node node(*lcm, o);
    livo::record::Recorder recorder(node, cli.get("--out"), channels);
    std::unique_ptr<livo::record::ArrivalThread> arrivals;
    if (cli.has("--arrivals"))
      arrivals = std::make_unique<livo::record::ArrivalThread>(cli.get("--lcm-url"), cli.get("--arrivals"));
    const int rc = livo::spin(*lcm, node, [&] {
      recorder.finish(o.health_channel);
      arrivals.reset();
    });
    std::cerr << "[" << o.name << "] wrote " << recorder.written() << " messages to " << cli.get("--out") << std::endl;
    return rc;
  } catch (const std::exception& e) {
    std::cerr << "livo-record: " << e.what() << std::endl;
    return 1;
  }
}
