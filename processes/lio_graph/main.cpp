// livo-lio-graph --config FILE: the second paper's LiDAR subsystem (factor graph) as an LCM process.
#include <iostream>

#include "livo/command_line.hpp"
#include "livo/config_check.hpp"
#include "livo/lio_graph/lio_graph_node.hpp"

int main(int argc, char** argv) {
  livo::CommandLine cli(
      "livo-lio-graph",
      "LIO-SAM-style LiDAR-inertial(-wheel) odometry on a fixed-lag factor graph: IMU + LIDAR (+ WHEEL) "
      "and LOOP_CORRECTION in, ODOMETRY, REGISTERED_SCAN and KEYFRAME out (a stand-in for livo-lio).");
  cli.option("--config", "FILE", "project config with rig: and (optional) lio_graph: sections")
      .option("--name", "NAME", "node name on the bus (overrides lio_graph.name)")
      .option("--lcm-url", "URL", "LCM provider (default: LCM_DEFAULT_URL or LCM's default)")
      .flag("--quiet", "no start-up options and no summary at shutdown");
  livo::declareConfigCheck(cli);
  if (!cli.parse(argc, argv)) return cli.exitCode();
  if (!cli.has("--config")) {
    std::cerr << "livo-lio-graph: --config FILE is required\n" << cli.usage();
    return 2;
  }
  try {
    const livo::Config cfg = livo::Config::load(cli.get("--config"));
    livo::lio_graph::LioGraphNodeOptions opts = livo::lio_graph::readLioGraphNodeOptions(cfg);
    if (cli.has("--name")) opts.name = cli.get("--name");
    const bool quiet = cli.has("--quiet");
    if (!quiet) livo::lio_graph::printOptions(opts, std::cerr);
    if (livo::configCheckDone(cli, std::cout)) return 0;
    auto lcm = livo::makeLcm(cli.has("--lcm-url") ? cli.get("--lcm-url") : "");
    livo::NodeOptions node_options;
    node_options.name = opts.name;
    node_options.quiet = quiet;
    livo::lio_graph::LioGraphNode node(*lcm, node_options, opts);
    livo::installSignalHandlers();
    const int rc = livo::spin(*lcm, node.node());
    if (!quiet) std::cerr << "[" << opts.name << "] " << node.summary() << "\n";
    return rc;
  } catch (const std::exception& e) {
    std::cerr << "livo-lio-graph: " << e.what() << std::endl;
    return 1;
  }
}
