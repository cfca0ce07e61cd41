// The files a pipeline run hands back: timing.json (per process: messages, median/p90/max ms,
// peak RSS) and report.md (accuracy, figures, where the estimate was weak, maps, timing, warnings).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "livo/report/calibration_course.hpp"
#include "livo/report/picture_set.hpp"
#include "livo/report/pipeline_outputs.hpp"
#include "livo/report/sensor_gaps.hpp"
#include "livo/report/weak_spots.hpp"

namespace livo::report {

/// Per process, from its final HEALTH. The headline numbers are those of its busiest input (the
/// one with the largest median x messages: the LiDAR for the LIO, images for the VIO), and every
/// input channel is listed under "channels".
nlohmann::json timingJson(const std::map<std::string, health_t>& final_health);

struct RunSummary {
  std::string log;            // input log
  std::string config;         // pipeline config
  double log_seconds = 0.0;   // replayed span
  double wall_seconds = 0.0;  // wall time of the replay
  std::string mode;           // "lockstep" or "real time"
  std::vector<std::string> processes;
};

/// One line of a supervised run's logs/restarts.tsv (written by scripts/run_pipeline.sh): when a
/// process ended, how, how long it was down and what its restart lost. Fields kept as written.
struct ProcessRestart {
  std::string wall_s;  // wall seconds after the replay started, when it ended
  std::string log_s;   // the replay's log time then (empty if unknown)
  std::string process;
  std::string ended;    // "killed by SIGKILL", "exited with code 0", ...
  std::string restart;  // restart number, or "-" when it was not restarted
  std::string down_s;   // wall seconds until the new instance started, or "-"
  std::string lost;     // what the restart lost
};

/// Reads restarts.tsv (7 tab-separated fields a line); a missing file is no restarts. Throws on a
/// malformed line.
std::vector<ProcessRestart> readRestarts(const std::string& path);

struct ReportInputs {
  RunSummary run;
  nlohmann::json timing;                                            // timingJson()
  std::vector<std::pair<std::string, nlohmann::json>> evaluations;  // title, livo-evaluate JSON
  std::vector<std::pair<std::string, std::string>> figures;         // caption, relative path
  std::vector<std::string> warnings;
  std::vector<std::string> injected_faults;  // playback's fault counts, one line per channel
  std::vector<std::string> sensor_use;       // what the estimators did with each sensor ("lio: wheel updates: ...")
  std::vector<ProcessRestart> restarts;
  bool supervised = false;                          // the run restarted processes that exited (the Restarts section)
  nlohmann::json resets = nlohmann::json::array();  // resetsJson(): LIO resets (odometry epochs)
  std::optional<WeakSpots> weak_spots;              // weak_spots.json: the "Where the estimate was weak" section
  std::optional<PictureSet> pictures;               // pictures.json (livo-report pictures): the "Maps" section
  std::optional<std::vector<SensorGapRow>> sensor_gaps;  // a live run's sensor_gaps.tsv: the "Sensor gaps" section
  std::vector<CalibrationRow> calibration;  // lio's calibration.csv: the "Calibration" section (none: no section)
  const PipelineOutputs* outputs = nullptr;
};

std::string reportMarkdown(const ReportInputs& in);

}  // namespace livo::report
