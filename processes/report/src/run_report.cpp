#include "livo/report/run_report.hpp"

#include <cmath>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <stdexcept>

#include "livo/report/latency.hpp"
#include "livo/text_format.hpp"

namespace livo::report {

nlohmann::json timingJson(const std::map<std::string, health_t>& final_health) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [node, h] : final_health) {
    nlohmann::json channels = nlohmann::json::object();
    const channel_stats_t* busiest = nullptr;
    int64_t total = 0;
    for (const auto& c : h.channels) {
      channels[c.channel] = {{"messages", c.messages},
                             {"median_ms", c.median_ms},
                             {"p90_ms", c.p90_ms},
                             {"max_ms", c.max_ms},
                             {"decode_failures", c.decode_failures},
                             {"rejected", c.rejected}};
      total += c.messages;
      if (!busiest || c.median_ms * c.messages > busiest->median_ms * busiest->messages) busiest = &c;
    }
    nlohmann::json p = {{"messages", busiest ? busiest->messages : 0},
                        {"median_ms", busiest ? busiest->median_ms : 0.0},
                        {"p90_ms", busiest ? busiest->p90_ms : 0.0},
                        {"max_ms", busiest ? busiest->max_ms : 0.0},
                        {"peak_rss_mb", h.peak_rss_mb},
                        {"busiest_channel", busiest ? busiest->channel : ""},
                        {"messages_all_channels", total},
                        {"channels", channels}};
    out[node] = p;
  }
  return out;
}

namespace {
std::string fixed(double v, int digits) { return std::isfinite(v) ? formatFixed(v, digits) : "n/a"; }
// j[a][b][c...] as a number, NaN when absent or null (a metric with no data).
double num(const nlohmann::json& j, std::initializer_list<const char*> path) {
  const nlohmann::json* node = &j;
  for (const char* key : path) {
    if (!node->is_object() || !node->contains(key)) return std::nan("");
    node = &(*node)[key];
  }
  return node->is_number() ? node->get<double>() : std::nan("");
}

// The table at the top: what was run, how, and what it produced.
std::string runTableMarkdown(const RunSummary& run, const PipelineOutputs* outputs, size_t resets) {
  std::ostringstream md;
  md << "# Pipeline run\n\n";
  md << "| | |\n| --- | --- |\n";
  md << "| log | `" << run.log << "` |\n";
  md << "| config | `" << run.config << "` |\n";
  md << "| processes | ";
  for (size_t i = 0; i < run.processes.size(); ++i) md << (i ? ", " : "") << run.processes[i];
  md << " |\n";
  md << "| replay | " << run.mode << ": " << fixed(run.log_seconds, 1) << " s of log in " << fixed(run.wall_seconds, 1)
     << " s wall";
  if (run.wall_seconds > 0) md << " (" << fixed(run.log_seconds / run.wall_seconds, 2) << "x real time)";
  md << " |\n";
  if (outputs) {
    md << "| odometry poses | " << outputs->odometry.size() << " |\n";
    md << "| keyframes | " << outputs->keyframes.size() << " |\n";
    md << "| loop corrections | " << outputs->loop_corrections << " |\n";
  }
  md << "| odometry resets | " << resets << " (epochs 0.." << resets << ") |\n";
  md << "\n";
  return md.str();
}

std::string resetsMarkdown(const nlohmann::json& resets) {
  if (resets.empty()) return "";
  std::ostringstream md;
  md << "## Odometry resets\n\n";
  md << "livo-lio re-initialised: the odometry restarted at the origin in a new epoch, and every consumer "
        "started over in it (loop: a new graph segment; vio, colour, octomap: a new map; the old maps are "
        "written as `*_epoch<N>.*`). Trajectories of different epochs are in unrelated frames.\n\n";
  md << "| time s | new epoch | reason |\n| --- | --- | --- |\n";
  for (const auto& r : resets) {
    const std::string reason = r.value("reason", std::string());
    md << "| " << fixed(r.value("time", 0.0), 3) << " | " << r.value("epoch", 0) << " | "
       << (reason.empty() ? "(not in HEALTH; see logs/lio.log)" : reason) << " |\n";
  }
  md << "\n";
  return md.str();
}

// A row per livo-evaluate JSON, and the alignment the first one used.
std::string accuracyMarkdown(const std::vector<std::pair<std::string, nlohmann::json>>& evaluations) {
  if (evaluations.empty()) return "## Accuracy\n\nNo ground truth in the log: no accuracy figures.\n\n";
  std::ostringstream md;
  md << "## Accuracy\n\n";
  md << "| trajectory | ATE RMSE m | mean m | median m | max m | coverage | RPE trans RMSE m | RPE rot RMSE deg |\n";
  md << "| --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const auto& [title, j] : evaluations) {
    md << "| " << title << " | " << fixed(num(j, {"ate", "rmse"}), 4) << " | " << fixed(num(j, {"ate", "mean"}), 4)
       << " | " << fixed(num(j, {"ate", "median"}), 4) << " | " << fixed(num(j, {"ate", "max"}), 4) << " | "
       << fixed(100.0 * num(j, {"ate", "coverage"}), 1) << " % | " << fixed(num(j, {"rpe", "translation", "rmse"}), 4)
       << " | " << fixed(num(j, {"rpe", "rotation", "rmse"}), 3) << " |\n";
  }
  const nlohmann::json& first = evaluations.front().second;
  const std::string mode =
      first.contains("alignment") && first["alignment"].contains("mode") && first["alignment"]["mode"].is_string()
          ? first["alignment"]["mode"].get<std::string>()
          : std::string("?");
  md << "\nATE: translation error after `" << mode << "` Umeyama alignment (`livo-evaluate`, as evo's `evo_ape`); "
     << "RPE between consecutive poses.\n\n";
  return md.str();
}

// Per process, its busiest input (timingJson()).
std::string processingTimeMarkdown(const nlohmann::json& timing) {
  std::ostringstream md;
  md << "## Processing time\n\n";
  md << "Per process, its busiest input (median x messages); `timing.json` lists every channel.\n\n";
  md << "| process | input | messages | median ms | p90 ms | max ms | peak RSS MB |\n";
  md << "| --- | --- | --- | --- | --- | --- | --- |\n";
  for (const auto& [node, p] : timing.items()) {
    md << "| " << node << " | " << p.value("busiest_channel", std::string()) << " | " << p.value("messages", 0) << " | "
       << fixed(p.value("median_ms", 0.0), 2) << " | " << fixed(p.value("p90_ms", 0.0), 2) << " | "
       << fixed(p.value("max_ms", 0.0), 2) << " | " << fixed(p.value("peak_rss_mb", 0.0), 1) << " |\n";
  }
  md << "\n";
  return md.str();
}

// A section of one bullet per line; none when there are no lines.
std::string listSection(const std::string& heading, const std::string& intro, const std::vector<std::string>& lines) {
  if (lines.empty()) return "";
  std::string md = "## " + heading + "\n\n" + intro + "\n\n";
  for (const auto& line : lines) md += "- " + line + "\n";
  return md + "\n";
}

std::string restartsMarkdown(const std::vector<ProcessRestart>& restarts) {
  if (restarts.empty()) return "## Restarts\n\nNone: no process exited during the run.\n\n";
  std::ostringstream md;
  md << "## Restarts\n\n";
  md << "| process | ended at (wall s) | log s | how | restart | down s | lost |\n";
  md << "| --- | --- | --- | --- | --- | --- | --- |\n";
  for (const auto& r : restarts)
    md << "| " << r.process << " | " << r.wall_s << " | " << (r.log_s.empty() ? "?" : r.log_s) << " | " << r.ended
       << " | " << r.restart << " | " << r.down_s << " | " << r.lost << " |\n";
  md << "\n";
  return md.str();
}

std::string warningsMarkdown(const std::vector<std::string>& warnings) {
  std::string md = "## Warnings\n\n";
  if (warnings.empty()) md += "None.\n";
  for (const auto& w : warnings) md += "- " + w + "\n";
  return md;
}

}  // namespace

std::vector<ProcessRestart> readRestarts(const std::string& path) {
  std::vector<ProcessRestart> out;
  std::ifstream f(path);
  if (!f) return out;
  std::string line;
  int number = 0;
  while (std::getline(f, line)) {
    ++number;
    if (line.empty()) continue;
    std::vector<std::string> fields;
    std::stringstream ss(line);
    std::string field;
    while (std::getline(ss, field, '\t')) fields.push_back(field);
    if (fields.size() != 7)
      throw std::runtime_error(path + ":" + std::to_string(number) + ": expected 7 tab-separated fields, got " +
                               std::to_string(fields.size()));
    out.push_back({fields[0], fields[1], fields[2], fields[3], fields[4], fields[5], fields[6]});
  }
  return out;
}

std::string reportMarkdown(const ReportInputs& in) {
  std::ostringstream md;
  md << runTableMarkdown(in.run, in.outputs, in.resets.size());
  md << resetsMarkdown(in.resets);
  md << accuracyMarkdown(in.evaluations);
  for (const auto& [caption, path] : in.figures) md << "![" << caption << "](" << path << ")\n\n";
  if (in.weak_spots) md << weakSpotsMarkdown(*in.weak_spots);
  if (in.pictures) md << mapsMarkdown(*in.pictures);
  md << processingTimeMarkdown(in.timing);
  md << latencyMarkdown(in.timing);
  if (!in.calibration.empty()) md << calibrationMarkdown(in.calibration);
  md << listSection("Sensor use",
                    "What the estimators did with their inputs, from their summaries at exit:", in.sensor_use);
  md << listSection("Injected faults",
                    "Faults injected by `livo-playback --faults` (seeded), per channel:", in.injected_faults);
  if (in.supervised || !in.restarts.empty()) md << restartsMarkdown(in.restarts);
  if (in.sensor_gaps) md << sensorGapsMarkdown(*in.sensor_gaps);
  md << warningsMarkdown(in.warnings);
  return md.str();
}

}  // namespace livo::report
