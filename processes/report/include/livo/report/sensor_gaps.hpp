// A live run's dead sensors (scripts/run_live.sh): logs/sensor_gaps.tsv as livo-sensor-watch
// writes it (processes/sensor_watch/include/livo/sensor_watch/gap_watch.hpp, writeGapLine), and
// report.md's "Sensor gaps" section listing each gap.
#pragma once

#include <string>
#include <vector>

namespace livo::report {

/// One line of sensor_gaps.tsv, fields kept as written.
struct SensorGapRow {
  std::string channel;
  std::string from_s;  // wall seconds after the run started: the last message before the gap
  std::string to_s;    // the first message after it, or the stop when `open`
  std::string length_s;
  bool open = false;         // still silent when the run stopped
  bool never = false;        // never heard in the run (open, from its start)
  std::string stamp_before;  // sensor stamps (s) bounding the gap, "-" when unknown
  std::string stamp_after;
};

/// Reads sensor_gaps.tsv (7 tab-separated fields a line, '#' lines skipped). Throws naming the file
/// and line on a malformed one; a missing file throws too (the watch always writes its header).
std::vector<SensorGapRow> readSensorGaps(const std::string& path);

/// "## Sensor gaps": a row per gap, or "None" when the watched sensors never stopped.
std::string sensorGapsMarkdown(const std::vector<SensorGapRow>& gaps);

}  // namespace livo::report
