// livo-vio-feature --config FILE: the second paper's visual subsystem (KLT features, a sliding
// window with IMU and wheel preintegration, RGB-D / LiDAR depth) as an LCM process.
#include <iostream>

#include "livo/command_line.hpp"
#include "livo/config_check.hpp"
#include "livo/vio_feature/vio_feature_node.hpp"

int main(int argc, char** argv) {
  livo::CommandLine cli(
      "livo-vio-feature",
      "Feature-based visual-inertial(-wheel) odometry on a sliding window: IMU + CAMERA (+ DEPTH, WHEEL, "
      "REGISTERED_SCAN for depth) in, VISUAL_STATE and VISUAL_ODOMETRY out.");
  cli.option("--config", "FILE", "project config with rig: and (optional) vio_feature: sections")
      .option("--name", "NAME", "node name on the bus (overrides vio_feature.name)")
      .option("--lcm-url", "URL", "LCM provider (default: LCM_DEFAULT_URL or LCM's default)")
      .flag("--quiet", "no start-up options and no summary at shutdown");
  livo::declareConfigCheck(cli);
  if (!cli.parse(argc, argv)) return cli.exitCode();
  if (!cli.has("--config")) {
    std::cerr << "livo-vio-feature: --config FILE is required\n" << cli.usage();
    return 2;
  }
  try {
    const livo::Config cfg = livo::Config::load(cli.get("--config"));
    livo::vio_feature::VioFeatureNodeOptions opts = livo::vio_feature::readVioFeatureNodeOptions(cfg);
    if (cli.has("--name")) opts.name = cli.get("--name");
    const bool quiet = cli.has("--quiet");
    if (!quiet) livo::vio_feature::printOptions(opts, std::cerr);
    if (livo::configCheckDone(cli, std::cout)) return 0;
    auto lcm = livo::makeLcm(cli.has("--lcm-url") ? cli.get("--lcm-url") : "");
    livo::NodeOptions node_options;
    node_options.name = opts.name;
    node_options.quiet = quiet;
    livo::vio_feature::VioFeatureNode node(*lcm, node_options, opts);
    livo::installSignalHandlers();
    const int rc = livo::spin(*lcm, node.node(), [&] { node.reportRefusals(); });
    if (!quiet) std::cerr << "[" << opts.name << "] " << node.summary() << "\n";
    return rc;
  } catch (const std::exception& e) {
    std::cerr << "livo-vio-feature: " << e.what() << std::endl;
    return 1;
  }
}
