// livo-vio --config FILE: the direct photometric VIO (STATE_PRIOR in, STATE_POSTERIOR out).
#include <cmath>
#include <iostream>

#include "livo/command_line.hpp"
#include "livo/config_check.hpp"
#include "livo/file_output.hpp"
#include "livo/vio/camera_rotation_calibration.hpp"
#include "livo/vio/vio_node.hpp"

namespace {

/// The camera rotation the image pairs found, fused with the rig's, as a config overlay for the
/// next run (rotation_calibration.overlay_file); nothing before min_pairs pairs.
void writeRotationOverlay(const livo::vio::VioNodeOptions& opts, const livo::vio::VioEstimator& vio, bool quiet) {
  const livo::vio::CameraRotationCalibration* cal = vio.rotationCalibration();
  const std::string& file = opts.vio.rotation_calibration.overlay_file;
  if (!cal || file.empty()) return;
  if (!cal->hasEstimate()) {
    std::cerr << "[" << opts.name << "] camera rotation: " << cal->pairsClosed() << " image pairs, too few for an estimate; "
              << file << " not written\n";
    return;
  }
  const double rig_std = opts.vio.update.calibration_rotation_std_deg * M_PI / 180.0;
  const livo::vio::FusedCameraRotation fused = livo::vio::fuseWithRig(opts.camera.T_I_C, cal->estimate(), rig_std);
  std::string error;
  if (!livo::writeFileAtomically(file, {livo::vio::cameraRotationOverlay(fused, cal->estimate(), cal->pairsClosed(), rig_std)},
                                 &error))
    std::cerr << "[" << opts.name << "] camera rotation: " << error << "\n";
  else if (!quiet)
    std::cerr << "[" << opts.name << "] camera rotation written to " << file << " (a config overlay)\n";
}

}  // namespace

int main(int argc, char** argv) {
  livo::CommandLine cli("livo-vio", "Sparse direct photometric update: CAMERA, STATE_PRIOR, REGISTERED_SCAN (and "
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
    writeRotationOverlay(opts, node.estimator(), quiet);
    if (!quiet && opts.vio.calibration.any()) {
      // what the online calibration learnt: the extrinsic against the rig's, and the time offset
      const livo::vio::VioEstimator& vio = node.estimator();
      const livo::Pose3 T = opts.camera.T_I_C.inverse() * vio.cameraExtrinsic();
      const livo::Vec3 phi = livo::so3::Log(T.linear()) * 180.0 / M_PI;
      std::cerr << "[" << opts.name << "] online calibration: camera rotation [" << phi.transpose()
                << "] deg, translation [" << T.translation().transpose() << "] m against the rig, image time offset "
                << vio.timeOffset() * 1e3 << " ms\n";
    }
    return status;
  } catch (const std::exception& e) {
    std::cerr << "livo-vio: " << e.what() << "\n";
    return 1;
  }
}
