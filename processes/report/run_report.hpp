// The files a pipeline run hands back: timing.json (per process: messages, median/p90/max ms,
// peak RSS) and report.md (timing, accuracy, figures, warnings).
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline_outputs.hpp"

namespace livo {

/// Per process, from its final HEALTH. The headline numbers are those of its busiest input (the
/// one with the largest median x messages: the LiDAR for the LIO, images for the VIO), and every
/// input channel is listed under "channels".
nlohmann::json timingJson(const std::map<std::string, health_t>& final_health);

struct RunSummary {
  std::string log;             // input log
  std::string config;          // pipeline config
  double log_seconds = 0.0;    // replayed span
  double wall_seconds = 0.0;   // wall time of the replay
  std::string mode;            // "lockstep" or "real time"
  std::vector<std::string> processes;
};

struct ReportInputs {
  RunSummary run;
  nlohmann::json timing;                                // timingJson()
  std::vector<std::pair<std::string, nlohmann::json>> evaluations;  // title, livo-evaluate JSON
  std::vector<std::pair<std::string, std::string>> figures;         // caption, relative path
  std::vector<std::string> warnings;
  nlohmann::json resets = nlohmann::json::array();  // resetsJson(): LIO resets (odometry epochs)
  const PipelineOutputs* outputs = nullptr;
};

std::string reportMarkdown(const ReportInputs& in);

}  // namespace livo
