#include "livo/playback/log_source.hpp"

#include <sys/stat.h>
#include <cstdio>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>

namespace livo::playback {

LogSource::LogSource(const std::string& path, LogSourceOptions options) : path_(path), options_(std::move(options)) {
  try {
    pattern_ = std::regex(options_.channels, std::regex::ECMAScript);
  } catch (const std::regex_error& e) {
    throw std::runtime_error("invalid channel pattern '" + options_.channels + "': " + e.what());
  }
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) throw std::runtime_error(path + ": no such file");
  file_bytes_ = st.st_size;
  log_ = std::make_unique<lcm::LogFile>(path, "r");
  if (!log_->good()) throw std::runtime_error(path + ": cannot open as an LCM log");
}

LogSource::~LogSource() = default;

double LogSource::fractionRead() const {
  if (file_bytes_ <= 0 || !log_) return 1.0;
  const long pos = std::ftell(log_->getFilePtr());
  return pos < 0 ? 1.0 : static_cast<double>(pos) / static_cast<double>(file_bytes_);
}

std::optional<LogEvent> LogSource::next() {
  while (!done_) {
    const lcm::LogEvent* ev = log_->readNextEvent();
    if (!ev) {
      done_ = true;
      trailing_bytes_ = file_bytes_ - last_good_pos_;
      break;
    }
    last_good_pos_ = std::ftell(log_->getFilePtr());
    if (first_utime_ < 0) first_utime_ = ev->timestamp;
    const double t = (ev->timestamp - first_utime_) * 1e-6;
    if (t < options_.start_s) continue;
    if (options_.duration_s > 0.0 && t > options_.start_s + options_.duration_s) {
      done_ = true;
      break;
    }
    auto match = matches_.find(ev->channel);
    if (match == matches_.end()) match = matches_.emplace(ev->channel, std::regex_match(ev->channel, pattern_)).first;
    if (!match->second) continue;
    LogEvent out;
    out.utime = ev->timestamp;
    out.channel = ev->channel;
    const auto* d = static_cast<const uint8_t*>(ev->data);
    out.data.assign(d, d + ev->datalen);
    return out;
  }
  return std::nullopt;
}

}  // namespace livo::playback
