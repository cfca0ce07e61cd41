#include "livo/evaluate/evaluate_command.hpp"

#include <cstdlib>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "livo/command_line.hpp"
#include "livo/evaluate/evaluation.hpp"
#include "livo/evaluate/json_report.hpp"
#include "livo/evaluate/scan_log.hpp"
#include "livo/evaluate/summary_tables.hpp"
#include "livo/evaluate/svg_plot.hpp"

namespace livo::evaluate {

namespace {

std::vector<double> parseNumberList(const std::string& option, const std::string& text) {
  std::vector<double> values;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0')
      throw std::invalid_argument(option + ": '" + item + "' is not a number (in '" + text + "')");
    values.push_back(v);
  }
  return values;
}

/// The ground-map thickness of the registered scans --ground-map names, against the ground truth.
GroundMapThickness groundMapOf(const CommandLine& cli, const TrajectoryInput& gt, const EvaluationOptions& evaluation) {
  if (!gt.has_stamps)
    throw std::invalid_argument("--ground-map needs a ground truth with time stamps (" + gt.path +
                                " is a KITTI pose file)");
  GroundMapOptions options;
  options.cell_m = cli.getDouble("--ground-cell");
  options.band_m = cli.getDouble("--ground-band");
  options.max_dt = cli.getDouble("--ground-max-dt");
  options.gt_offset = evaluation.gt_offset;
  options.validate();
  const ScanLogInput scans = scanLogInput(cli.get("--ground-map"), "REGISTERED_SCAN");
  GroundMapThickness g = groundMapThickness(registeredScanSource(scans), gt.poses, options);
  g.source = scans.spec == scans.path ? scans.path + ":" + scans.channel : scans.spec;
  return g;
}

std::string baseName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// The command line: its options and what each means.
CommandLine evaluateCommandLine() {
  CommandLine cli("livo-evaluate",
                  "Absolute trajectory error, relative pose error and KITTI drift of an estimated trajectory against\n"
                  "ground truth. Inputs: TUM files, KITTI pose files (paired by index), EuRoC csv, or LCM logs\n"
                  "(LOG or LOG:CHANNEL; livo.pose_t or livo.odometry_t messages). Numbers as evo's evo_ape/evo_rpe.");
  cli.option("--est", "E", "estimated trajectory: file, LCM log (channel ODOMETRY) or LOG:CHANNEL")
      .option("--gt", "G", "ground truth: file, LCM log (channel GROUND_TRUTH) or LOG:CHANNEL")
      .option("--align", "MODE",
              "alignment of the estimate: se3 or sim3 (Umeyama), 4dof (yaw about z and "
              "translation) or none",
              "se3")
      .option("--max-dt", "S", "largest stamp gap of an associated pair, seconds", "0.01")
      .option("--gt-offset", "X,Y,Z", "point on the body (body frame, m) the ground truth tracks, e.g. a prism")
      .option("--rpe-delta", "N", "RPE over N frames", "1")
      .flag("--rpe-all-pairs", "RPE over every pair (i, i+N) rather than i = 0, N, 2N, ...")
      .option("--drift-lengths", "L1,L2,...", "KITTI drift segment lengths, m", "100,200,300,400,500,600,700,800")
      .option("--drift-step", "N", "KITTI drift: a segment starts every N poses", "10")
      .option("--coverage-gap", "S", "longest interval between pairs that counts as covered, s (default: 3x median)")
      .option("--ground-map", "LOG[:CHANNEL]",
              "also the ground-map thickness of the registered scans "
              "(livo.registered_scan_t, channel REGISTERED_SCAN) against --gt")
      .option("--ground-cell", "M", "ground map: side of the square cells, m", "0.5")
      .option("--ground-band", "M", "ground map: the ground layer, m above a cell's 5th percentile height", "0.2")
      .option("--ground-max-dt", "S",
              "ground map: a scan's ground truth is interpolated between poses at most S "
              "before and after it",
              "0.05")
      .option("--json", "F", "write the figures as JSON")
      .option("--plot", "F", "write a figure (SVG): top view coloured by error, errors over time")
      .option("--marks", "F",
              "mark on the figure the degenerate and predicted stretches and the loop closures of a "
              "pipeline run (its weak_spots.json, from livo-report extract)")
      .option("--report", "F", "write a Markdown report with the tables, embedding the --plot figure")
      .option("--title", "T", "title of the figure and report (default: estimate vs ground truth)")
      .flag("--quiet", "print nothing on success");
  return cli;
}

// The evaluation's options from the command line, validated.
EvaluationOptions evaluationOptions(const CommandLine& cli) {
  EvaluationOptions options;
  options.alignment = parseAlignment(cli.get("--align"));
  options.max_dt = cli.getDouble("--max-dt");
  if (cli.has("--gt-offset")) {
    const auto v = parseNumberList("--gt-offset", cli.get("--gt-offset"));
    if (v.size() != 3) throw std::invalid_argument("--gt-offset: expected x,y,z, got '" + cli.get("--gt-offset") + "'");
    options.gt_offset = Vec3(v[0], v[1], v[2]);
  }
  options.rpe.delta = static_cast<int>(cli.getInt("--rpe-delta"));
  options.rpe.all_pairs = cli.has("--rpe-all-pairs");
  options.drift.segment_lengths = parseNumberList("--drift-lengths", cli.get("--drift-lengths"));
  options.drift.step = static_cast<int>(cli.getInt("--drift-step"));
  if (cli.has("--coverage-gap")) options.coverage_gap = cli.getDouble("--coverage-gap");
  options.validate();
  return options;
}

}  // namespace

int runEvaluateCommand(int argc, char** argv, std::ostream& out, std::ostream& err) {
  CommandLine cli = evaluateCommandLine();
  if (!cli.parse(argc, argv)) return cli.exitCode();

  try {
    if (!cli.has("--est") || !cli.has("--gt")) throw std::invalid_argument("--est and --gt are both required");
    if (cli.has("--marks") && !cli.has("--plot"))
      throw std::invalid_argument("--marks draws on the figure: give --plot F too");
    const EvaluationOptions options = evaluationOptions(cli);
    const TrajectoryInput est = readTrajectoryInput(cli.get("--est"), "ODOMETRY");
    const TrajectoryInput gt = readTrajectoryInput(cli.get("--gt"), "GROUND_TRUTH");
    Evaluation ev = evaluateTrajectory(est, gt, options);
    if (cli.has("--ground-map")) ev.ground_map = groundMapOf(cli, gt, options);

    if (!cli.has("--quiet")) printSummary(out, ev, est, gt, options);
    const std::string title = cli.has("--title") ? cli.get("--title")
                                                 : baseName(est.spec) + " vs " + baseName(gt.spec) + " (" +
                                                       alignmentName(options.alignment) + " aligned)";
    if (cli.has("--json")) writeEvaluationJson(cli.get("--json"), ev, est, gt, options);
    if (cli.has("--plot")) {
      PlotOptions plot;
      plot.title = title;
      if (cli.has("--marks")) plot.marks = readPlotMarks(cli.get("--marks"));
      writeEvaluationSvg(cli.get("--plot"), ev, plot);
    }
    if (cli.has("--report"))
      writeMarkdownReport(cli.get("--report"), ev, est, gt, options, cli.has("--plot") ? cli.get("--plot") : "");
  } catch (const std::exception& e) {
    err << "livo-evaluate: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace livo::evaluate
