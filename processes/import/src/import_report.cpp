#include "livo/import/import_report.hpp"

#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>

namespace livo::import {

void ImportReport::skip(const std::string& reason, const std::string& where, int64_t count, bool warn) {
  Skipped& s = skipped_[reason];
  if (s.count == 0) {
    s.first_where = where;
    if (!quiet_ && warn)
      std::cerr << "livo-import: warning: skipped: " << reason << "\n    first at: " << where
                << " (further ones counted)\n";
  }
  s.count += count;
}

void ImportReport::error(const std::string& message) {
  errors_.push_back(message);
  if (!quiet_) std::cerr << "livo-import: error: " << message << "\n";
}

void ImportReport::note(const std::string& message) { notes_.push_back(message); }

void ImportReport::metadata(const std::string& key, const std::string& yaml_value) {
  for (auto& kv : metadata_)
    if (kv.first == key) {
      kv.second = yaml_value;
      return;
    }
  metadata_.emplace_back(key, yaml_value);
}

void ImportReport::metadataString(const std::string& key, const std::string& value) { metadata(key, yamlQuote(value)); }

std::string ImportReport::metadataValue(const std::string& key) const {
  for (const auto& kv : metadata_)
    if (kv.first == key) return kv.second;
  return "";
}

int64_t ImportReport::skippedTotal() const {
  int64_t n = 0;
  for (const auto& kv : skipped_) n += kv.second.count;
  return n;
}

void ImportReport::print(std::ostream& os, const std::map<std::string, int64_t>& channel_counts,
                         const std::map<std::string, std::string>& channel_types) const {
  size_t w = 7;
  for (const auto& kv : channel_counts) w = std::max(w, kv.first.size());
  os << std::left << std::setw(static_cast<int>(w) + 2) << "channel" << std::setw(22) << "type" << std::right
     << std::setw(10) << "messages"
     << "\n";
  int64_t total = 0;
  for (const auto& [channel, count] : channel_counts) {
    const auto t = channel_types.find(channel);
    os << std::left << std::setw(static_cast<int>(w) + 2) << channel << std::setw(22)
       << (t == channel_types.end() ? "" : t->second) << std::right << std::setw(10) << count << "\n";
    total += count;
  }
  os << std::left << std::setw(static_cast<int>(w) + 2) << "total" << std::setw(22) << "" << std::right << std::setw(10)
     << total << "\n";
  if (!skipped_.empty()) {
    os << "skipped (" << skippedTotal() << "):\n";
    for (const auto& [reason, s] : skipped_)
      os << "  " << std::setw(8) << s.count << "  " << reason << "  (first: " << s.first_where << ")\n";
  }
  for (const std::string& e : errors_) os << "error: " << e << "\n";
  for (const std::string& n : notes_) os << "note: " << n << "\n";
  if (!metadata_.empty()) {
    os << "metadata:\n";
    for (const auto& [k, v] : metadata_) os << "  " << k << ": " << v << "\n";
  }
}

void ImportReport::writeSidecar(const std::string& path, const std::string& format, const std::string& input,
                                const std::string& log_path,
                                const std::map<std::string, int64_t>& channel_counts) const {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write the metadata sidecar");
  out << "# Written by livo-import beside " << log_path << ": what the log's messages cannot carry.\n";
  out << "format: " << yamlQuote(format) << "\n";
  out << "input: " << yamlQuote(input) << "\n";
  out << "log: " << yamlQuote(log_path) << "\n";
  out << "channels:\n";
  for (const auto& [c, n] : channel_counts) out << "  " << yamlQuote(c) << ": " << n << "\n";
  out << "metadata:" << (metadata_.empty() ? " {}" : "") << "\n";
  for (const auto& [k, v] : metadata_) out << "  " << k << ": " << v << "\n";
  out << "skipped:" << (skipped_.empty() ? " []" : "") << "\n";
  for (const auto& [reason, s] : skipped_)
    out << "  - {reason: " << yamlQuote(reason) << ", count: " << s.count << ", first: " << yamlQuote(s.first_where)
        << "}\n";
  out << "errors:" << (errors_.empty() ? " []" : "") << "\n";
  for (const std::string& e : errors_) out << "  - " << yamlQuote(e) << "\n";
  out << "notes:" << (notes_.empty() ? " []" : "") << "\n";
  for (const std::string& n : notes_) out << "  - " << yamlQuote(n) << "\n";
  if (!out) throw std::runtime_error(path + ": write failed");
}

std::string yamlQuote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\x%02x", static_cast<unsigned char>(c));
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string yamlNumber(double v) {
  v += 0.0;                                                 // no "-0"
  for (int precision = 15; precision <= 17; ++precision) {  // shortest text that reads back exactly
    std::ostringstream os;
    os << std::setprecision(precision) << v;
    if (precision == 17 || std::stod(os.str()) == v) return os.str();
  }
  return "";
}

std::string yamlList(const std::vector<double>& values) {
  std::string out = "[";
  for (size_t i = 0; i < values.size(); ++i) out += (i ? ", " : "") + yamlNumber(values[i]);
  return out + "]";
}

}  // namespace livo::import
