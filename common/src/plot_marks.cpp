#include "livo/plot_marks.hpp"

#include <fstream>
#include <limits>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace livo {

namespace {

std::vector<std::pair<double, double>> spans(const nlohmann::json& j) {
  std::vector<std::pair<double, double>> out;
  for (const auto& s : j.at("spans")) out.emplace_back(s.at("from").get<double>(), s.at("to").get<double>());
  return out;
}

double stampOrNan(const nlohmann::json& j) {  // JSON has no NaN: an unknown stamp is null
  return j.is_number() ? j.get<double>() : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

PlotMarks readPlotMarks(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the plot marks");
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    PlotMarks m;
    m.degenerate = spans(j.at("degenerate"));
    m.predicted = spans(j.at("predicted"));
    for (const auto& l : j.at("loops"))
      m.loops.push_back({l.at("time").get<double>(), stampOrNan(l.at("from_time")), stampOrNan(l.at("to_time"))});
    return m;
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(path + ": not a weak_spots.json (livo-report extract): " + e.what());
  }
}

}  // namespace livo
