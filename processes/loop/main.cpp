// livo-loop --config FILE: coarse-to-fine loop closure (Quatro, then Nano-GICP) and pose-graph
// correction; publishes LOOP_CORRECTION, writes keyframes.tum, loops.json and global_map.ply.
#include <iostream>

#include "livo/command_line.hpp"
#include "livo/config.hpp"
#include "livo/config_check.hpp"
#include "livo/loop/loop_node.hpp"
#include "livo/node.hpp"

int main(int argc, char** argv) {
  livo::CommandLine cli("livo-loop", "Loop closure: Quatro + Nano-GICP registration and pose-graph correction.");
  cli.option("--config", "FILE", "project config (reads the optional loop: section)")
      .option("--name", "N", "node name on the bus", "loop")
      .option("--output-dir", "DIR",
              "write keyframes.tum, loops.json and global_map.ply here (overrides loop.output_dir)")
      .option("--lcm-url", "URL", "LCM URL (default: $LCM_DEFAULT_URL)")
      .flag("--quiet", "no option summary at start, no summary at shutdown");
  livo::declareConfigCheck(cli);
  if (!cli.parse(argc, argv)) return cli.exitCode();
  if (!cli.has("--config")) {
    std::cerr << "livo-loop: --config FILE is required\n" << cli.usage();
    return 2;
  }
  try {
    const livo::Config config = livo::Config::load(cli.get("--config"));
    livo::loop::LoopNodeOptions options = livo::loop::readLoopNodeOptions(config);
    if (cli.has("--output-dir")) options.output_dir = cli.get("--output-dir");
    if (!cli.has("--quiet")) livo::loop::printOptions(options, std::cerr);
    if (livo::configCheckDone(cli, std::cout)) return 0;
    livo::NodeOptions node_options;
    node_options.name = cli.get("--name");
    node_options.quiet = cli.has("--quiet");
    auto lcm = livo::makeLcm(cli.get("--lcm-url"));
    livo::loop::LoopNode node(*lcm, node_options, options);
    livo::installSignalHandlers();
    return livo::spin(*lcm, node.node(), [&] { node.writeOutputs(); });
  } catch (const std::exception& e) {
    std::cerr << "livo-loop: " << e.what() << std::endl;
    return 1;
  }
}
