#include "livo/reason_counts.hpp"

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <vector>

namespace livo {

namespace {
const char* const kTag = " by reason: ";
const char* const kTimes = " x ";
}  // namespace

std::string ReasonCounts::key(const std::string& why) {
  std::string k = why.substr(0, why.find(" ("));
  std::replace(k.begin(), k.end(), ';', ',');
  return k;
}

void ReasonCounts::add(const std::string& why, int64_t times) { counts_[key(why)] += times; }

int64_t ReasonCounts::total() const {
  int64_t n = 0;
  for (const auto& [why, count] : counts_) n += count;
  return n;
}

std::string ReasonCounts::summary(const std::string& what) const {
  if (counts_.empty()) return "";
  std::vector<std::pair<std::string, int64_t>> order(counts_.begin(), counts_.end());
  std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  std::ostringstream s;
  s << what << kTag;
  for (size_t i = 0; i < order.size(); ++i) s << (i ? "; " : "") << order[i].second << kTimes << order[i].first;
  return s.str();
}

std::optional<ParsedReasonCounts> parseReasonCounts(const std::string& text) {
  const size_t tag = text.find(kTag);
  if (tag == std::string::npos || tag == 0) return std::nullopt;
  ParsedReasonCounts out;
  out.what = text.substr(0, tag);
  std::stringstream items(text.substr(tag + std::string(kTag).size()));
  std::string item;
  while (std::getline(items, item, ';')) {
    if (!item.empty() && item.front() == ' ') item.erase(0, 1);
    const size_t times = item.find(kTimes);
    if (times == std::string::npos || times == 0) return std::nullopt;
    char* end = nullptr;
    const long long n = std::strtoll(item.c_str(), &end, 10);
    if (end != item.c_str() + times || n <= 0) return std::nullopt;
    out.reasons.add(item.substr(times + std::string(kTimes).size()), n);
  }
  if (out.reasons.empty()) return std::nullopt;
  return out;
}

}  // namespace livo
