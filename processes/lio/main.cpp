// livo-lio --config FILE: the ESIKF LiDAR-inertial odometry as an LCM process.
#include <cstdlib>
#include <iostream>

#include "livo/command_line.hpp"
#include "livo/config_check.hpp"
#include "livo/lio/lio_node.hpp"

int main(int argc, char** argv) {
  livo::CommandLine cli("livo-lio",
                        "ESIKF LiDAR-inertial odometry: IMU + LIDAR (+ WHEEL) in, ODOMETRY, "
                        "REGISTERED_SCAN and KEYFRAME out.");
  cli.option("--config", "FILE", "project config with rig: and (optional) lio: sections")
      .option("--name", "NAME", "node name on the bus (overrides lio.name)")
      .option("--lcm-url", "URL", "LCM provider (default: LCM_DEFAULT_URL or LCM's default)")
      .flag("--quiet", "no start-up options and no summary at shutdown");
  livo::declareConfigCheck(cli);
  if (!cli.parse(argc, argv)) return cli.exitCode();
  if (!cli.has("--config")) {
    std::cerr << "livo-lio: --config FILE is required\n" << cli.usage();
    return 2;
  }
  try {
    const livo::Config cfg = livo::Config::load(cli.get("--config"));
    livo::lio::LioNodeOptions opts = livo::lio::readLioNodeOptions(cfg);
    if (cli.has("--name")) opts.name = cli.get("--name");
    // supervised runs (scripts/run_pipeline.sh --respawn): the numbering survives a restart
    if (const char* dir = std::getenv("LIVO_STATE_DIR"); dir && *dir) {
      opts.numbering_file = std::string(dir) + "/" + opts.name + ".numbering";
      const char* restarts = std::getenv("LIVO_RESTARTS");
      opts.continue_numbering = restarts && std::atoi(restarts) > 0;
    }
    const bool quiet = cli.has("--quiet");
    if (!quiet) livo::lio::printOptions(opts, std::cerr);
    if (livo::configCheckDone(cli, std::cout)) return 0;
    auto lcm = livo::makeLcm(cli.has("--lcm-url") ? cli.get("--lcm-url") : "");
    livo::lio::LioNode node(*lcm, opts, quiet);
    livo::installSignalHandlers();
    const int rc = livo::spin(*lcm, node.node());
    node.writeCalibrationFiles();
    if (!quiet) std::cerr << "[" << opts.name << "] " << node.sweepSummary() << "\n";
    if (const std::string c = node.calibrationSummary(); !quiet && !c.empty())
      std::cerr << "[" << opts.name << "] " << c << "\n";
    if (!quiet && opts.core.wheel.enabled) std::cerr << "[" << opts.name << "] " << node.wheelSummary() << "\n";
    if (!quiet && opts.camera_handoff) {
      const auto& h = node.handoffCounts();
      std::cerr << "[" << opts.name << "] camera hand-off: " << h.priors << " priors, " << h.adopted
                << " posteriors adopted, " << h.kept_prior << " kept the prior, " << h.missing
                << " unanswered (went on LiDAR-only), " << h.no_vio << " images with no VIO running, "
                << h.images_skipped << " images before tracking or late\n";
    }
    return rc;
  } catch (const std::exception& e) {
    std::cerr << "livo-lio: " << e.what() << "\n";
    return 1;
  }
}
