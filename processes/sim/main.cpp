// livo-sim --config config/sim/NAME.yaml --out LOG [--overlay FILE,...] [--duration S] [--seed N] [--threads N]
//          [--no-images]
#include <cmath>
#include <iomanip>
#include <iostream>

#include "livo/command_line.hpp"
#include "livo/config_overlays.hpp"
#include "livo/file_output.hpp"
#include "livo/sim/log_writer.hpp"
#include "livo/sim/simulation_setup.hpp"
#include "livo/sim/simulator.hpp"

int main(int argc, char** argv) {
  livo::CommandLine cli(
      "livo-sim", "Simulates IMU, LiDAR, camera, wheel encoder and ground truth in a scene and writes an LCM log.");
  cli.option("--config", "FILE", "sim config (rig: and sim: sections), e.g. config/sim/room.yaml")
      .option("--out", "LOG", "LCM log file to write")
      .option("--overlay", "FILE[,FILE]",
              "YAML merged over the config in order (maps key by key, other values replaced), e.g. "
              "config/sim/controls/exact_imu.yaml: the same scene and seed with some sensor errors off")
      .option("--duration", "S", "seconds to simulate (default: sim.duration_s)")
      .option("--seed", "N", "random seed (default: sim.seed)")
      .option("--threads", "N", "worker threads (default: sim.threads; the log does not depend on it)")
      .option("--truth", "FILE",
              "also write the run's truth as JSON: the calibration errors drawn and the rig as "
              "rendered (for evaluation scripts; no estimator reads it)")
      .flag("--no-images",
            "leave out the camera's (and depth) images: a log for LiDAR-only runs in a fraction of "
            "the time, every other channel as it is with them")
      .flag("--quiet", "no progress output");
  if (!cli.parse(argc, argv)) return cli.exitCode();
  if (!cli.has("--config") || !cli.has("--out")) {
    std::cerr << "livo-sim: --config and --out are required\n" << cli.usage();
    return 2;
  }
  try {
    livo::sim::SimOverrides overrides;
    if (cli.has("--duration")) overrides.duration_s = cli.getDouble("--duration");
    if (cli.has("--seed")) {
      const int64_t seed = cli.getInt("--seed");
      if (seed < 0) throw std::invalid_argument("--seed: must be >= 0");
      overrides.seed = static_cast<uint64_t>(seed);
    }
    if (cli.has("--threads")) {
      const int64_t t = cli.getInt("--threads");
      if (t < 1 || t > 256) throw std::invalid_argument("--threads: must be in 1..256");
      overrides.threads = static_cast<int>(t);
    }
    overrides.no_images = cli.has("--no-images");
    if (cli.has("--overlay")) overrides.overlays = livo::overlayFiles(cli.get("--overlay"));
    const bool quiet = cli.has("--quiet");
    livo::sim::SimulationSetup setup = livo::sim::loadSimulation(cli.get("--config"), overrides);
    if (!quiet) livo::sim::printSimulation(setup, std::cerr);

    if (cli.has("--truth")) {
      std::string error;
      if (!livo::writeFileAtomically(cli.get("--truth"), {livo::sim::truthJson(setup)}, &error))
        throw std::runtime_error("--truth: " + error);
    }
    livo::sim::LogWriter writer(cli.get("--out"), setup.rig.channels);
    livo::sim::Simulator simulator(setup);
    double next_report = 0.0;
    const auto stats = simulator.run(writer, [&](double done, double total, const livo::sim::SimulationStats& st) {
      if (quiet || done + 1e-9 < next_report) return;
      std::cerr << std::fixed << std::setprecision(1) << "[" << std::setw(5) << 100.0 * done / total << "%] sim "
                << done << " / " << total << " s, wall " << st.wall_seconds << " s\n";
      next_report = std::floor(done / total * 20.0 + 1.0) * total / 20.0;
    });
    std::cerr << std::fixed << std::setprecision(2) << "livo-sim: wrote " << cli.get("--out") << ": "
              << stats.sim_seconds << " s simulated in " << stats.wall_seconds << " s wall ("
              << stats.sim_seconds / std::max(stats.wall_seconds, 1e-9) << "x real time), "
              << writer.bytesWritten() / 1e6 << " MB\n";
    for (const auto& [channel, count] : stats.messages)
      std::cerr << "  " << std::left << std::setw(14) << channel << count << " messages\n";
    if (setup.rig.lidar) std::cerr << "  LiDAR points: " << stats.lidar_points << "\n";
    if (setup.rig.wheel && setup.options.wheel_slip.enabled())
      std::cerr << "  wheel slip episodes: " << stats.wheel_slip_episodes << "\n";
  } catch (const std::exception& e) {
    std::cerr << "livo-sim: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
