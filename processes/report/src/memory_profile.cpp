#include "livo/report/memory_profile.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include <lcm/lcm-cpp.hpp>

#include "livo/health_t.hpp"

namespace livo::report {

double MemoryProfile::peakAt(const std::string& node, double seconds) const {
  auto it = samples.find(node);
  // the run's last HEALTH comes up to a health period before the log's end: a checkpoint at the
  // run's duration (soak_pipeline.sh's last one) still counts as reached
  if (it == samples.end() || seconds > last_seconds - first_seconds + kEndSlack_s) return std::nan("");
  double peak = std::nan("");
  for (const auto& [t, mb] : it->second) {
    if (t > seconds) break;
    peak = std::isnan(peak) ? mb : std::max(peak, mb);
  }
  return peak;
}

MemoryProfile readMemoryProfile(const std::string& log_path, const std::string& health_channel) {
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw std::runtime_error(log_path + ": cannot open as an LCM log");
  std::vector<std::tuple<int64_t, std::string, double>> all;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    if (ev->channel != health_channel) continue;
    health_t h;
    if (h.decode(ev->data, 0, ev->datalen) != ev->datalen || h.utime <= 0) continue;  // before any input
    all.emplace_back(h.utime, h.node, h.peak_rss_mb);
  }
  MemoryProfile p;
  if (all.empty()) return p;
  std::stable_sort(all.begin(), all.end(),
                   [](const auto& a, const auto& b) { return std::get<0>(a) < std::get<0>(b); });
  p.first_seconds = std::get<0>(all.front()) * 1e-6;
  p.last_seconds = std::get<0>(all.back()) * 1e-6;
  for (const auto& [utime, node, mb] : all) p.samples[node].emplace_back(utime * 1e-6 - p.first_seconds, mb);
  return p;
}

std::string memoryTable(const MemoryProfile& profile, const std::vector<double>& checkpoints_s) {
  auto cell = [](double v) {
    if (std::isnan(v)) return std::string("-");
    std::ostringstream s;
    s << std::fixed << std::setprecision(1) << v;
    return s.str();
  };
  std::ostringstream md;
  md << "peak RSS (MB) at sensor time; run spans " << std::fixed << std::setprecision(1)
     << profile.last_seconds - profile.first_seconds << " s\n\n| process |";
  for (double c : checkpoints_s) md << " " << cell(c / 60.0) << " min |";
  md << " last / first | whole run |\n| --- |";
  for (size_t i = 0; i < checkpoints_s.size() + 2; ++i) md << " --- |";
  md << "\n";
  for (const auto& [node, samples] : profile.samples) {
    md << "| " << node << " |";
    std::vector<double> at;
    for (double c : checkpoints_s) {
      at.push_back(profile.peakAt(node, c));
      md << " " << cell(at.back()) << " |";
    }
    double whole = 0.0;
    for (const auto& s : samples) whole = std::max(whole, s.second);
    const double ratio = at.size() >= 2 ? at.back() / at.front() : std::nan("");
    std::ostringstream r;
    if (!std::isnan(ratio)) r << std::fixed << std::setprecision(3) << ratio;
    md << " " << (std::isnan(ratio) ? "-" : r.str()) << " | " << cell(whole) << " |\n";
  }
  return md.str();
}

}  // namespace livo::report
