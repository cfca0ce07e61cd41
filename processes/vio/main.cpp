// livo-vio --config FILE: the direct photometric VIO (STATE_PRIOR in, STATE_POSTERIOR out).
#include <iostream>

#include "livo/command_line.hpp"
#include "livo/config_check.hpp"
#include "livo/vio/vio_node.hpp"

int main(int argc, char** argv) {
  livo::CommandLine cli("livo-vio",
                        "Sparse direct photometric update: CAMERA, STATE_PRIOR, REGISTERED_SCAN (and "
                        "LOOP_CORRECTION) in, STATE_POSTERIOR out.");
  cli.option("--config", "FILE", "project config with rig: (with a camera) and (optional) vio: sections")
      .option("--name", "NAME", "node name on the bus (overrides vio.name)")
      .option("--lcm-url", "URL", "LCM provider (default: LCM_DEFAULT_URL or LCM's default)")
      .flag("--quiet", "no start-up options and no summary at shutdown");
  livo::declareConfigCheck(cli);
  if (!cli.parse(argc, argv)) return cli.exitCode();
  if (!cli.has("--config")) {
    std::cerr << "livo-vio: --config FILE is required\n" << cli.usage();
    return 2;
  }
  try {
    const livo::Config cfg = livo::Config::load(cli.get("--config"));
    livo::vio::VioNodeOptions opts = livo::vio::readVioNodeOptions(cfg);
    if (cli.has("--name")) opts.name = cli.get("--name");
    const bool quiet = cli.has("--quiet");
    if (!quiet) livo::vio::printOptions(opts, std::cerr);
    if (livo::configCheckDone(cli, std::cout)) return 0;
    auto lcm = livo::makeLcm(cli.has("--lcm-url") ? cli.get("--lcm-url") : "");
    livo::vio::VioNode node(*lcm, opts, quiet);
    livo::installSignalHandlers();
    const int status = livo::spin(*lcm, node.node(), [&] { node.reportKeptReasons(); });
    return status;
  } catch (const std::exception& e) {
    std::cerr << "livo-vio: " << e.what() << "\n";
    return 1;
  }
}
