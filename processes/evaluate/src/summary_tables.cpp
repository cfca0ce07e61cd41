#include "livo/evaluate/summary_tables.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace livo::evaluate {

namespace {

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  bool numeric = true;  // right-align every column but the first

  void text(std::ostream& os, bool with_header = true) const {
    std::vector<size_t> w(header.size(), 0);
    for (size_t c = 0; c < header.size(); ++c) w[c] = header[c].size();
    for (const auto& r : rows)
      for (size_t c = 0; c < r.size(); ++c) w[c] = std::max(w[c], r[c].size());
    auto line = [&](const std::vector<std::string>& r) {
      for (size_t c = 0; c < r.size(); ++c) {
        if (c == 0 || !numeric)
          os << (c ? "  " : "") << std::left << std::setw(c + 1 == r.size() ? 0 : static_cast<int>(w[c])) << r[c];
        else
          os << "  " << std::right << std::setw(static_cast<int>(w[c])) << r[c];
      }
      os << "\n";
    };
    if (with_header) line(header);
    for (const auto& r : rows) line(r);
  }

  void markdown(std::ostream& os) const {
    auto line = [&](const std::vector<std::string>& r) {
      os << "|";
      for (const auto& cell : r) os << " " << cell << " |";
      os << "\n";
    };
    line(header);
    os << "|";
    for (size_t c = 0; c < header.size(); ++c) os << (c == 0 || !numeric ? " --- |" : " ---: |");
    os << "\n";
    for (const auto& r : rows) line(r);
  }
};

std::string num(double v, int precision = 6) {
  std::ostringstream os;
  os << std::setprecision(precision) << v;
  return os.str();
}

std::string fixed(double v, int decimals) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(decimals) << v;
  return os.str();
}

std::string signedFixed(double v, int decimals) {
  std::ostringstream os;
  os << std::showpos << std::fixed << std::setprecision(decimals) << v;
  return os.str();
}

Table errorTable(const Evaluation& ev) {
  Table t{{"error", "rmse", "mean", "median", "std", "min", "max", "count"}, {}};
  auto row = [&](const std::string& name, const ErrorStatistics& s) {
    if (s.count == 0) {
      t.rows.push_back({name, "-", "-", "-", "-", "-", "-", "0"});
      return;
    }
    t.rows.push_back(
        {name, num(s.rmse), num(s.mean), num(s.median), num(s.std), num(s.min), num(s.max), std::to_string(s.count)});
  };
  row("ATE translation (m)", ev.ate);
  row("RPE translation (m)", ev.rpe_translation_m);
  row("RPE rotation (deg)", ev.rpe_rotation_deg);
  return t;
}

Table driftTable(const Evaluation& ev) {
  Table t{{"segment (m)", "segments", "translation (%)", "rotation (deg/m)"}, {}};
  for (const auto& d : ev.drift.per_length) {
    if (d.segments == 0)
      t.rows.push_back({num(d.length_m), "0", "-", "-"});
    else
      t.rows.push_back(
          {num(d.length_m), std::to_string(d.segments), fixed(d.translation_percent, 4), num(d.rotation_deg_per_m, 6)});
  }
  if (ev.drift.segments > 0)
    t.rows.push_back({"all", std::to_string(ev.drift.segments), fixed(ev.drift.translation_percent, 4),
                      num(ev.drift.rotation_deg_per_m, 6)});
  return t;
}

Table inputTable(const Evaluation& ev, const TrajectoryInput& est, const TrajectoryInput& gt,
                 const EvaluationOptions& options) {
  Table t{{"input", "value"}, {}, false};
  t.rows.push_back({"estimate", est.spec + " (" + est.format + ", " + std::to_string(est.poses.size()) + " poses)"});
  t.rows.push_back({"ground truth", gt.spec + " (" + gt.format + ", " + std::to_string(gt.poses.size()) + " poses)"});
  std::string pairing =
      std::to_string(ev.pairs.size()) + " pairs " +
      (ev.pairs.by_index ? std::string("by index") : "by time, max dt " + num(options.max_dt) + " s") + ", " +
      fixed(100.0 * static_cast<double>(ev.pairs.size()) / static_cast<double>(ev.est_poses), 1) + " % of the estimate";
  t.rows.push_back({"pairs", pairing});
  std::string alignment = alignmentName(options.alignment);
  if (options.alignment == Alignment::kSim3) alignment += ", scale " + num(ev.alignment.scale, 8);
  if (options.alignment == Alignment::kFourDof)
    alignment +=
        " (yaw about z and translation), yaw " + fixed(yawOf(ev.alignment.rotation) * 180.0 / M_PI, 4) + " deg";
  t.rows.push_back({"alignment", alignment});
  if (!options.gt_offset.isZero())
    t.rows.push_back({"gt offset (body, m)", num(options.gt_offset.x()) + ", " + num(options.gt_offset.y()) + ", " +
                                                 num(options.gt_offset.z())});
  const std::string unit = ev.pairs.by_index ? " frames" : " s";
  t.rows.push_back({"coverage", fixed(100.0 * ev.coverage.fraction, 2) + " % of " + num(ev.coverage.span) + unit +
                                    " (gaps up to " + num(ev.coverage.gap, 4) + unit + " count)"});
  t.rows.push_back({"RPE pairs", "delta " + std::to_string(options.rpe.delta) + " frame" +
                                     (options.rpe.delta == 1 ? "" : "s") +
                                     (options.rpe.all_pairs ? ", all pairs" : ", consecutive pairs")});
  return t;
}

std::string endPointLine(const Evaluation& ev) {
  std::ostringstream os;
  os << "End-point drift (anchored at the first pose): " << fixed(ev.end_point.translation_m, 4) << " m, "
     << fixed(ev.end_point.rotation_deg, 3) << " deg over " << fixed(ev.end_point.path_length_m, 1) << " m ("
     << fixed(ev.end_point.percent(), 3) << " %)";
  return os.str();
}

std::string fourDofAteLine(const Evaluation& ev) {
  if (ev.ate_4dof.count == 0)
    return "ATE after a 4-DoF alignment (yaw about z and translation): undefined (no horizontal spread)";
  return "ATE after a 4-DoF alignment (yaw about z and translation): rmse " + num(ev.ate_4dof.rmse) + " m";
}

std::string verticalDriftLine(const Evaluation& ev) {
  std::ostringstream os;
  os << "Vertical drift (z error, heights anchored at the first pose): " << signedFixed(ev.vertical.end_m, 4)
     << " m at the end";
  if (ev.vertical.hasPath()) os << ", " << signedFixed(ev.vertical.per100m(), 4) << " m per 100 m";
  os << " over " << fixed(ev.vertical.path_length_m, 1) << " m; largest |z error| " << fixed(ev.vertical.max_abs_m, 4)
     << " m";
  return os.str();
}

std::string attitudeLine(const Evaluation& ev) {
  const AttitudeError& a = ev.attitude;
  return "Roll / pitch error (gravity direction in the body, rmse): roll " + fixed(a.roll.rmse, 4) + " deg, pitch " +
         fixed(a.pitch.rmse, 4) + " deg, tilt " + fixed(a.tilt.rmse, 4) + " deg (largest tilt " + fixed(a.tilt.max, 4) +
         " deg)";
}

std::string groundMapLine(const GroundMapThickness& g) {
  std::ostringstream os;
  os << "Ground-map thickness (" << g.source << ", " << num(g.cell_m) << " m cells, the lowest " << num(g.band_m)
     << " m of each): ";
  if (g.cells == 0)
    os << "no cell with 10 ground points from 2 scans";
  else
    os << "rms " << fixed(g.thickness.rmse, 4) << " m, median " << fixed(g.thickness.median, 4)
       << " m; truth floor rms " << fixed(g.truth.rmse, 4) << " m, median " << fixed(g.truth.median, 4) << " m; "
       << g.cells << " cells, " << g.points << " ground points";
  os << "; " << g.scans << " scans";
  if (g.scans_skipped > 0)
    os << ", " << g.scans_skipped << " skipped (" << g.scans_empty << " empty, the rest without ground truth)";
  if (g.points_skipped > 0) os << ", " << g.points_skipped << " points skipped (not finite, or beyond the cell grid)";
  return os.str();
}

/// The lines of the metrics for a ground vehicle, each ending in a newline; `separator` between them.
void groundVehicleLines(std::ostream& os, const Evaluation& ev, const std::string& separator) {
  os << fourDofAteLine(ev) << "\n"
     << separator << verticalDriftLine(ev) << "\n"
     << separator << attitudeLine(ev) << "\n";
  if (ev.ground_map) os << separator << groundMapLine(*ev.ground_map) << "\n";
}

}  // namespace

void printSummary(std::ostream& os, const Evaluation& ev, const TrajectoryInput& est, const TrajectoryInput& gt,
                  const EvaluationOptions& options) {
  inputTable(ev, est, gt, options).text(os, false);
  os << "\n";
  errorTable(ev).text(os);
  os << "\n" << endPointLine(ev) << "\n";
  groundVehicleLines(os, ev, "");
  if (ev.drift.segments == 0) {
    os << "KITTI drift: no segment (the ground-truth path, " << fixed(ev.drift.path_length_m, 1)
       << " m, is shorter than the shortest segment length)\n";
    return;
  }
  os << "KITTI drift (segments from every " << options.drift.step << " poses)\n";
  driftTable(ev).text(os);
}

void writeMarkdownReport(const std::string& path, const Evaluation& ev, const TrajectoryInput& est,
                         const TrajectoryInput& gt, const EvaluationOptions& options, const std::string& plot_path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write");
  out << "# Trajectory evaluation\n\n";
  inputTable(ev, est, gt, options).markdown(out);
  out << "\n## Errors\n\nATE after " << alignmentName(options.alignment) << " alignment; RPE of the relative pose over "
      << options.rpe.delta << " frame" << (options.rpe.delta == 1 ? "" : "s") << ".\n\n";
  errorTable(ev).markdown(out);
  out << "\n" << endPointLine(ev) << "\n";
  out << "\n";
  groundVehicleLines(out, ev, "\n");
  out << "\n## KITTI drift\n\n";
  if (ev.drift.segments == 0) {
    out << "No segment: the ground-truth path (" << fixed(ev.drift.path_length_m, 1)
        << " m) is shorter than the shortest segment length.\n";
  } else {
    out << "Segments of the ground-truth path starting every " << options.drift.step
        << " poses; translation error in % of the segment length, rotation error per metre.\n\n";
    driftTable(ev).markdown(out);
  }
  if (!plot_path.empty()) {
    namespace fs = std::filesystem;
    const fs::path report_dir = fs::absolute(fs::path(path)).parent_path();
    const std::string rel =
        fs::absolute(fs::path(plot_path)).lexically_normal().lexically_relative(report_dir.lexically_normal()).string();
    out << "\n## Figures\n\n![Top view coloured by ATE, and errors over time](" << rel << ")\n";
  }
  if (!out) throw std::runtime_error(path + ": write failed");
}

}  // namespace livo::evaluate
