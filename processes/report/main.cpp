// livo-report: turns a pipeline run's recorded outputs into the files the user gets back.
//   livo-report extract OUTPUTS.lcmlog --dir DIR     odometry.tum, trajectory.tum, timing.json,
//                                                    resets.json, weak_spots.json
//   livo-report pictures --dir DIR [...]             trajectory_top.svg, map_top.png, map_oblique.png,
//                                                    octomap_slice.png, pictures.json from the run's files
//   livo-report markdown --dir DIR [...]             report.md from those and livo-evaluate's JSON
//   livo-report html --dir DIR [...]                 report.html: report.md self-contained, the map in 3D
//   livo-report memory OUTPUTS.lcmlog [--at S,S,...]  peak RSS per process at sensor times (HEALTH)
#include <chrono>
#include <fstream>
#include <iostream>
#include <sstream>

#include "livo/command_line.hpp"
#include "livo/file_output.hpp"
#include "livo/report/html_report.hpp"
#include "livo/report/latency.hpp"
#include "livo/report/memory_profile.hpp"
#include "livo/report/pipeline_outputs.hpp"
#include "livo/report/run_pictures.hpp"
#include "livo/report/run_report.hpp"
#include "livo/report/weak_spots.hpp"
#include "livo/text_format.hpp"

namespace {

std::vector<std::string> splitList(const std::string& s, char sep = ',') {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, sep))
    if (!item.empty()) out.push_back(item);
  return out;
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) throw std::runtime_error(path + ": cannot write");
}

int extract(int argc, char** argv) {
  livo::CommandLine cli("livo-report extract",
                        "Writes odometry.tum, trajectory.tum, timing.json, resets.json and "
                        "weak_spots.json from a run's outputs log.");
  cli.positional("OUTPUTS", "LCM log recorded during the run (lcm-logger)")
      .option("--dir", "DIR", "where to write the files", ".")
      .option("--odometry-channel", "CH", "online estimate", "ODOMETRY")
      .option("--keyframe-channel", "CH", "keyframes", "KEYFRAME")
      .option("--loop-channel", "CH", "loop corrections", "LOOP_CORRECTION")
      .option("--health-channel", "CH", "node health", "HEALTH")
      .option("--prior-channel", "CH", "images handed to the VIO (STATE_PRIOR)", "STATE_PRIOR")
      .option("--posterior-channel", "CH", "the VIO's answers (STATE_POSTERIOR)", "STATE_POSTERIOR")
      .option("--camera-channel", "CH", "images (named in the VIOs' HEALTH)", "CAMERA")
      .option("--colored-cloud-channel", "CH", "the coloured map's updates (latency)", "COLORED_CLOUD")
      .option("--arrivals", "FILE",
              "real time: livo-record --arrivals of the run, for each output's latency in timing.json")
      .option("--traces", "DIR", "with --arrivals: where the processes' LIVO_LATENCY_TRACE files (P.trace.tsv) are");
  if (!cli.parse(argc, argv)) return cli.exitCode();
  livo::report::PipelineChannels ch;
  ch.odometry = cli.get("--odometry-channel");
  ch.keyframe = cli.get("--keyframe-channel");
  ch.loop_correction = cli.get("--loop-channel");
  ch.health = cli.get("--health-channel");
  ch.state_prior = cli.get("--prior-channel");
  ch.state_posterior = cli.get("--posterior-channel");
  ch.camera = cli.get("--camera-channel");
  const livo::report::PipelineOutputs out = livo::report::readPipelineOutputs(cli.get("OUTPUTS"), ch);
  const std::string dir = cli.get("--dir");
  livo::writeTum(dir + "/odometry.tum", out.odometry);
  std::vector<std::string> trajectory_warnings;
  livo::writeTum(dir + "/trajectory.tum", livo::report::loopCorrectedTrajectory(out, &trajectory_warnings));
  nlohmann::json timing = livo::report::timingJson(out.final_health);
  if (cli.has("--arrivals")) {
    const auto traces = cli.has("--traces") ? livo::report::readPublishTraceDir(cli.get("--traces"))
                                            : std::vector<livo::report::PublishTrace>{};
    const auto latency = livo::report::computeLatency(
        livo::report::readArrivals(cli.get("--arrivals")), traces,
        livo::report::defaultLatencySpecs(ch.odometry, ch.state_posterior, cli.get("--colored-cloud-channel")));
    livo::report::addLatency(latency, &timing);
    for (const auto& c : latency)
      std::cerr << "livo-report: latency of " << c.channel << ": " << c.messages << " messages, p50 "
                << livo::formatFixed(c.p50_ms, 1) << " ms, p99 " << livo::formatFixed(c.p99_ms, 1) << " ms, max "
                << livo::formatFixed(c.max_ms, 1) << " ms\n";
  }
  writeText(dir + "/timing.json", timing.dump(2) + "\n");
  writeText(dir + "/resets.json", livo::report::resetsJson(out.resets));
  const livo::report::WeakSpots weak = livo::report::findWeakSpots(out, ch.camera);
  writeText(dir + "/weak_spots.json", livo::report::weakSpotsJson(weak).dump(2) + "\n");
  std::cerr << "livo-report: " << out.odometry.size() << " odometry poses, " << out.keyframes.size() << " keyframes, "
            << out.loop_corrections << " loop corrections, health of " << out.final_health.size() << " processes; "
            << weak.degenerate << " degenerate and " << weak.predicted << " predicted sweeps\n";
  for (const std::string& w : trajectory_warnings) std::cerr << "livo-report: warning: " << w << "\n";
  if (out.undecodable) std::cerr << "livo-report: warning: " << out.undecodable << " messages did not decode\n";
  if (out.non_finite) std::cerr << "livo-report: warning: " << out.non_finite << " odometry poses were not finite\n";
  if (out.odometry.empty()) {
    std::cerr << "livo-report: no " << ch.odometry << " messages in " << cli.get("OUTPUTS") << "\n";
    return 1;
  }
  return 0;
}

int markdown(int argc, char** argv) {
  livo::CommandLine cli("livo-report markdown", "Writes DIR/report.md from DIR/timing.json, evaluations and figures.");
  cli.option("--dir", "DIR", "the run's output folder", ".")
      .option("--log", "LOG", "the replayed log")
      .option("--config", "FILE", "the pipeline config")
      .option("--processes", "A,B", "processes that ran")
      .option("--mode", "M", "lockstep or real time", "lockstep")
      .option("--log-seconds", "S", "replayed span of the log", "0")
      .option("--wall-seconds", "S", "wall time of the replay", "0")
      .option("--evaluation", "TITLE=FILE;...", "livo-evaluate JSON files with their titles")
      .option("--figure", "CAPTION=FILE;...", "figures (paths relative to DIR)")
      .option("--warning", "TEXT;...", "warnings to list")
      .option("--injected", "TEXT;...", "faults injected by playback, one entry per channel")
      .option("--sensor-use", "TEXT;...",
              "what the estimators did with each sensor, one entry per line of their summaries")
      .option("--restarts", "FILE", "a supervised run's restarts.tsv (scripts/run_pipeline.sh --respawn)")
      .option("--sensor-gaps", "FILE", "a live run's sensor_gaps.tsv (livo-sensor-watch, scripts/run_live.sh)");
  if (!cli.parse(argc, argv)) return cli.exitCode();
  const std::string dir = cli.get("--dir");
  livo::report::ReportInputs in;
  in.run.log = cli.get("--log");
  in.run.config = cli.get("--config");
  in.run.processes = splitList(cli.get("--processes"));
  in.run.mode = cli.get("--mode");
  in.run.log_seconds = cli.getDouble("--log-seconds");
  in.run.wall_seconds = cli.getDouble("--wall-seconds");
  {
    std::ifstream t(dir + "/timing.json");
    if (!t) throw std::runtime_error(dir + "/timing.json: missing (run livo-report extract first)");
    in.timing = nlohmann::json::parse(t);
  }
  for (const auto& item : splitList(cli.get("--evaluation"), ';')) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos) throw std::invalid_argument("--evaluation: expected TITLE=FILE, got " + item);
    std::ifstream f(item.substr(eq + 1));
    if (!f) {
      in.warnings.push_back("evaluation " + item.substr(eq + 1) + " is missing");
      continue;
    }
    in.evaluations.emplace_back(item.substr(0, eq), nlohmann::json::parse(f));
  }
  for (const auto& item : splitList(cli.get("--figure"), ';')) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos) throw std::invalid_argument("--figure: expected CAPTION=FILE, got " + item);
    in.figures.emplace_back(item.substr(0, eq), item.substr(eq + 1));
  }
  for (const auto& w : splitList(cli.get("--warning"), ';')) in.warnings.push_back(w);
  for (const auto& f : splitList(cli.get("--injected"), ';')) in.injected_faults.push_back(f);
  for (const auto& f : splitList(cli.get("--sensor-use"), ';')) in.sensor_use.push_back(f);
  if (!cli.get("--restarts").empty()) {
    in.supervised = true;
    in.restarts = livo::report::readRestarts(cli.get("--restarts"));
  }
  if (!cli.get("--sensor-gaps").empty()) in.sensor_gaps = livo::report::readSensorGaps(cli.get("--sensor-gaps"));
  if (std::ifstream r(dir + "/resets.json"); r) in.resets = nlohmann::json::parse(r);
  if (std::ifstream c(dir + "/calibration.csv"); c)
    in.calibration = livo::report::readCalibrationCsv(dir + "/calibration.csv");
  if (std::ifstream p(dir + "/pictures.json"); p)
    in.pictures = livo::report::picturesFromJson(nlohmann::json::parse(p));
  if (std::ifstream w(dir + "/weak_spots.json"); w)
    in.weak_spots = livo::report::weakSpotsFromJson(nlohmann::json::parse(w));
  else
    in.warnings.push_back(
        "weak_spots.json is missing (livo-report extract writes it): no \"Where the estimate was weak\"");
  for (const auto& [node, p] : in.timing.items()) {
    for (const auto& [channel, c] : p["channels"].items()) {
      if (c.value("decode_failures", 0) > 0)
        in.warnings.push_back(node + ": " + std::to_string(c.value("decode_failures", 0)) + " messages on " + channel +
                              " did not decode");
      if (c.value("rejected", 0) > 0)
        in.warnings.push_back(node + ": " + std::to_string(c.value("rejected", 0)) + " messages on " + channel +
                              " were rejected (see its log)");
    }
  }
  writeText(dir + "/report.md", livo::report::reportMarkdown(in));
  std::cout << dir << "/report.md\n";
  return 0;
}

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int pictures(int argc, char** argv) {
  livo::CommandLine cli("livo-report pictures",
                        "Draws the run's maps and trajectory beside its report: trajectory_top.svg, map_top.png, "
                        "map_oblique.png, octomap_slice.png and pictures.json (what was drawn; notes on what was not). "
                        "Run it before `livo-report markdown`, which shows them.");
  const livo::report::PictureOptions d;
  cli.option("--dir", "DIR", "the run's output folder", ".")
      .option("--colour-map", "FILE", "the RGB map (binary PLY), relative to DIR", d.colour_map)
      .option("--octomap", "FILE", "the OctoMap (.bt), relative to DIR", d.octomap)
      .option("--cut-above", "M", "RGB map pictures: leave out points higher above the trajectory",
              livo::formatSignificant(d.cut_above_m))
      .option("--slice-below", "M", "OctoMap slice: from this far below the trajectory",
              livo::formatSignificant(d.band.below_m))
      .option("--slice-above", "M", "OctoMap slice: to this far above it", livo::formatSignificant(d.band.above_m))
      .option("--point-size", "M", "the RGB map's point spacing", livo::formatSignificant(d.point_size_m))
      .option("--size", "PX", "the pictures' longer side", std::to_string(d.long_side_px));
  if (!cli.parse(argc, argv)) return cli.exitCode();
  livo::report::PictureOptions o;
  o.colour_map = cli.get("--colour-map");
  o.octomap = cli.get("--octomap");
  o.cut_above_m = cli.getDouble("--cut-above");
  o.band.below_m = cli.getDouble("--slice-below");
  o.band.above_m = cli.getDouble("--slice-above");
  o.point_size_m = cli.getDouble("--point-size");
  o.long_side_px = static_cast<int>(cli.getInt("--size"));
  if (o.long_side_px < 100 || o.long_side_px > 10000)
    throw std::invalid_argument("--size: between 100 and 10000 pixels");
  if (!(o.point_size_m > 0) || !(o.band.below_m + o.band.above_m > 0))
    throw std::invalid_argument("--point-size and the slice's band must be positive");
  const std::string dir = cli.get("--dir");
  const auto t0 = std::chrono::steady_clock::now();
  const livo::report::PictureSet set = livo::report::makePictures(dir, o, &std::cerr);
  std::string error;
  if (!livo::writeFileAtomically(dir + "/pictures.json", {livo::report::picturesJson(set).dump(2) + "\n"}, &error))
    throw std::runtime_error(error);
  for (const auto& n : set.notes) std::cerr << "livo-report pictures: " << n << "\n";
  std::cerr << "livo-report pictures: " << set.pictures.size() << (set.pictures.size() == 1 ? " picture" : " pictures")
            << " in " << livo::formatFixed(secondsSince(t0), 2) << " s\n";
  for (const auto& p : set.pictures) std::cout << dir << "/" << p.file << "\n";
  return 0;
}

int html(int argc, char** argv) {
  livo::CommandLine cli("livo-report html",
                        "Writes DIR/report.html: DIR/report.md as one self-contained page (pictures and scripts "
                        "inlined, nothing from a network) with the RGB map and the trajectory in 3D (three.js from "
                        "libjs-three). Run it after `livo-report markdown`.");
  const livo::report::HtmlOptions d;
  cli.option("--dir", "DIR", "the run's output folder", ".")
      .option("--out", "FILE", "the page (default DIR/report.html)")
      .option("--colour-map", "FILE", "the RGB map (binary PLY), relative to DIR", d.colour_map)
      .option("--max-points", "N", "at most this many map points in the 3D view (thinned on a voxel grid)",
              std::to_string(d.viewer.max_points))
      .option("--three-dir", "DIR", "where three.min.js and examples/js/controls/OrbitControls.js are", d.three_dir);
  if (!cli.parse(argc, argv)) return cli.exitCode();
  livo::report::HtmlOptions o;
  o.colour_map = cli.get("--colour-map");
  o.three_dir = cli.get("--three-dir");
  if (cli.getInt("--max-points") < 1) throw std::invalid_argument("--max-points: at least 1");
  o.viewer.max_points = static_cast<size_t>(cli.getInt("--max-points"));
  const std::string dir = cli.get("--dir");
  const std::string out = cli.has("--out") ? cli.get("--out") : dir + "/report.html";
  const auto t0 = std::chrono::steady_clock::now();
  const livo::report::HtmlReport page = livo::report::reportHtml(dir, o);
  std::string error;
  if (!livo::writeFileAtomically(out, {page.html}, &error)) throw std::runtime_error(error);
  for (const auto& w : page.warnings) std::cerr << "livo-report html: warning: " << w << "\n";
  std::cerr << "livo-report html: " << livo::formatFixed(page.html.size() / 1048576.0, 1) << " MB, ";
  if (!page.viewer)
    std::cerr << "no 3D view" << (page.three_missing ? "" : " (no map, no trajectory)");
  else if (page.map_points == 0)
    std::cerr << "the trajectory in 3D (no map)";
  else
    std::cerr << page.points_shown << " of " << page.map_points << " map points in 3D";
  if (page.voxel_m > 0) std::cerr << " (" << livo::formatSignificant(page.voxel_m, 3) << " m voxels)";
  std::cerr << ", " << livo::formatFixed(secondsSince(t0), 2) << " s\n";
  std::cout << out << "\n";
  if (page.three_missing) {
    std::cerr << "livo-report html: error: no 3D view in " << out << ": three.js is missing (" << o.three_dir
              << "/three.min.js, " << o.three_dir << "/examples/js/controls/OrbitControls.js); install Debian's "
              << "libjs-three (sudo apt-get install libjs-three) and run livo-report html again. The rest of the "
              << "report is written.\n";
    return 1;
  }
  return 0;
}

int memory(int argc, char** argv) {
  livo::CommandLine cli(
      "livo-report memory",
      "Prints each process's peak RSS at sensor times, from the HEALTH messages of a run's outputs log.");
  cli.positional("OUTPUTS", "LCM log recorded during the run")
      .option("--at", "S,S,...", "seconds of sensor time since the first HEALTH", "300,900,1800")
      .option("--health-channel", "CH", "node health", "HEALTH");
  if (!cli.parse(argc, argv)) return cli.exitCode();
  std::vector<double> at;
  for (const std::string& s : splitList(cli.get("--at"))) at.push_back(std::stod(s));
  const livo::report::MemoryProfile p =
      livo::report::readMemoryProfile(cli.get("OUTPUTS"), cli.get("--health-channel"));
  if (p.samples.empty()) {
    std::cerr << "livo-report: no HEALTH messages with a sensor time in " << cli.get("OUTPUTS") << "\n";
    return 1;
  }
  std::cout << livo::report::memoryTable(p, at);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string usage =
      "usage: livo-report extract OUTPUTS.lcmlog --dir DIR | livo-report pictures --dir DIR [...] | "
      "livo-report markdown --dir DIR [...] | livo-report html --dir DIR [...] | "
      "livo-report memory OUTPUTS.lcmlog [--at S,...]\n";
  if (argc < 2) {
    std::cerr << usage;
    return 2;
  }
  const std::string cmd = argv[1];
  try {
    if (cmd == "extract") return extract(argc - 1, argv + 1);
    if (cmd == "markdown") return markdown(argc - 1, argv + 1);
    if (cmd == "pictures") return pictures(argc - 1, argv + 1);
    if (cmd == "html") return html(argc - 1, argv + 1);
    if (cmd == "memory") return memory(argc - 1, argv + 1);
    if (cmd == "--help") {
      std::cout << usage;
      return 0;
    }
  } catch (const std::exception& e) {
    std::cerr << "livo-report: " << e.what() << "\n";
    return 1;
  }
  std::cerr << "livo-report: unknown command '" << cmd << "'\n" << usage;
  return 2;
}
