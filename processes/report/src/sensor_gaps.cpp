#include "livo/report/sensor_gaps.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace livo::report {

std::vector<SensorGapRow> readSensorGaps(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot read");
  std::vector<SensorGapRow> out;
  std::string line;
  for (int number = 1; std::getline(f, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    std::stringstream ss(line);
    for (std::string field; std::getline(ss, field, '\t');) fields.push_back(field);
    if (fields.size() != 7 || (fields[4] != "back" && fields[4] != "open" && fields[4] != "never"))
      throw std::runtime_error(
          path + ":" + std::to_string(number) +
          ": expected channel, from_s, to_s, length_s, back|open|never and two stamps, tab-separated");
    out.push_back(
        {fields[0], fields[1], fields[2], fields[3], fields[4] != "back", fields[4] == "never", fields[5], fields[6]});
  }
  return out;
}

std::string sensorGapsMarkdown(const std::vector<SensorGapRow>& gaps) {
  std::ostringstream md;
  md << "## Sensor gaps\n\n";
  if (gaps.empty()) return md.str() + "None: the IMU and LiDAR were never silent for the watch's gap (a second).\n\n";
  md << "Watched sensors that sent nothing for a second or more (wall clock, `livo-sensor-watch`); the "
        "estimators went on from their next message. Times are seconds after the run started; the stamps "
        "are the sensor's own, of the messages either side.\n\n";
  md << "| channel | from s | to s | length s | sensor stamps s |\n| --- | --- | --- | --- | --- |\n";
  for (const auto& g : gaps)
    md << "| " << g.channel << " | " << g.from_s << " | "
       << (g.never  ? "the stop (never heard)"
           : g.open ? "the stop (still silent)"
                    : g.to_s)
       << " | " << g.length_s << " | " << g.stamp_before << " .. " << (g.open ? "-" : g.stamp_after) << " |\n";
  md << "\n";
  return md.str();
}

}  // namespace livo::report
