// livo-octomap --config FILE [--name N] [--output-dir DIR] [--lcm-url URL]: the OctoMap export.
#include <iostream>

#include "livo/command_line.hpp"
#include "livo/config_check.hpp"
#include "livo/octomap/octomap_node.hpp"

int main(int argc, char** argv) {
  livo::CommandLine cli("livo-octomap",
                        "Builds an OctoMap from registered scans; publishes OCTOMAP and writes .bt/.ot files.");
  cli.option("--config", "FILE", "project config (rig:, optional octomap:)")
      .option("--name", "NAME", "node name on the bus", "octomap")
      .option("--output-dir", "DIR", "where the .bt/.ot files go", ".")
      .option("--lcm-url", "URL", "LCM provider (default: LCM_DEFAULT_URL or LCM's default)")
      .flag("--quiet", "no option summary at start");
  livo::declareConfigCheck(cli);
  if (!cli.parse(argc, argv)) return cli.exitCode();
  if (!cli.has("--config")) {
    std::cerr << "livo-octomap: --config is required\n" << cli.usage();
    return 2;
  }
  try {
    const livo::Config cfg = livo::Config::load(cli.get("--config"));
    const livo::SensorRig rig = livo::readSensorRig(cfg.section("rig"));
    const auto options = livo::octomap::readOctomapNodeOptions(cfg);
    if (!cli.has("--quiet")) livo::octomap::printOptions(options, std::cerr);
    if (livo::configCheckDone(cli, std::cout)) return 0;
    livo::installSignalHandlers();
    auto lcm = livo::makeLcm(cli.has("--lcm-url") ? cli.get("--lcm-url") : "");
    livo::NodeOptions node_options;
    node_options.name = cli.get("--name");
    livo::octomap::OctomapNode node(*lcm, node_options, options, rig, cli.get("--output-dir"));
    return livo::spin(*lcm, node.node(), [&] { node.finish(); });
  } catch (const std::exception& e) {
    std::cerr << "livo-octomap: " << e.what() << std::endl;
    return 1;
  }
}
