// livo-colour --config FILE [--name N] [--output-dir DIR] [--lcm-url URL]: the RGB point-cloud map.
#include <iostream>

#include "livo/colour/colour_node.hpp"
#include "livo/command_line.hpp"
#include "livo/config_check.hpp"

int main(int argc, char** argv) {
  livo::CommandLine cli(
      "livo-colour",
      "Colours registered scans from the camera images; publishes COLORED_CLOUD and writes the map as PLY/PCD.");
  cli.option("--config", "FILE", "project config (rig: with a camera, optional colour:)")
      .option("--name", "NAME", "node name on the bus", "colour")
      .option("--output-dir", "DIR", "where the map files go", ".")
      .option("--lcm-url", "URL", "LCM provider (default: LCM_DEFAULT_URL or LCM's default)")
      .flag("--quiet", "no option summary at start");
  livo::declareConfigCheck(cli);
  if (!cli.parse(argc, argv)) return cli.exitCode();
  if (!cli.has("--config")) {
    std::cerr << "livo-colour: --config is required\n" << cli.usage();
    return 2;
  }
  try {
    const livo::Config cfg = livo::Config::load(cli.get("--config"));
    const livo::SensorRig rig = livo::colour::readColourRig(cfg);
    const livo::colour::ColourNodeOptions options = livo::colour::readColourNodeOptions(cfg);
    if (!cli.has("--quiet")) livo::colour::printOptions(options, std::cerr);
    if (livo::configCheckDone(cli, std::cout)) return 0;
    livo::installSignalHandlers();
    auto lcm = livo::makeLcm(cli.has("--lcm-url") ? cli.get("--lcm-url") : "");
    livo::NodeOptions node_options;
    node_options.name = cli.get("--name");
    livo::colour::ColourNode node(*lcm, node_options, options, rig, cli.get("--output-dir"));
    return livo::spin(*lcm, node.node(), [&] { node.finish(); });
  } catch (const std::exception& e) {
    std::cerr << "livo-colour: " << e.what() << std::endl;
    return 1;
  }
}
