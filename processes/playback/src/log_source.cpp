#include "livo/playback/log_source.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace livo::playback {

namespace {
constexpr uint32_t kSyncWord = 0xEDA1DA01;  // lcm_eventlog's MAGIC, big-endian before every event
constexpr int64_t kHeaderBytes = 8 + 8 + 4 + 4;  // event number, timestamp, channel and data lengths

uint64_t bigEndian(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return v;
}
}  // namespace

LogSource::LogSource(const std::string& path, LogSourceOptions options) : path_(path), options_(std::move(options)) {
  try {
    pattern_ = std::regex(options_.channels, std::regex::ECMAScript);
  } catch (const std::regex_error& e) {
    throw std::runtime_error("invalid channel pattern '" + options_.channels + "': " + e.what());
  }
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    struct stat st {};
    throw std::runtime_error(path + (stat(path.c_str(), &st) != 0 ? ": no such file" : ": cannot open as an LCM log"));
  }
  struct stat st {};
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw std::runtime_error(path + ": cannot open as an LCM log (not a regular file)");
  }
  file_bytes_ = st.st_size;
  if (file_bytes_ > 0) {
    void* m = mmap(nullptr, static_cast<size_t>(file_bytes_), PROT_READ, MAP_PRIVATE, fd, 0);
    if (m == MAP_FAILED) {
      ::close(fd);
      throw std::runtime_error(path + ": cannot map the log: " + std::strerror(errno));
    }
    map_ = static_cast<const uint8_t*>(m);
  }
  ::close(fd);  // the mapping stays
}

LogSource::~LogSource() {
  if (map_) munmap(const_cast<uint8_t*>(map_), static_cast<size_t>(file_bytes_));
}

double LogSource::fractionRead() const {
  return file_bytes_ <= 0 ? 1.0 : static_cast<double>(pos_) / static_cast<double>(file_bytes_);
}

bool LogSource::readEvent(int64_t* utime, std::string_view* channel, const uint8_t** data, int64_t* size) {
  // The format lcm_eventlog writes. Bytes before the next sync word are skipped and counted (LCM's
  // reader gives up there instead, with the event before); a header with an impossible length, or
  // an event cut short by the end of the file, ends the log, as in LCM.
  uint32_t sync = 0;
  int64_t p = pos_;
  while (sync != kSyncWord) {
    if (p >= file_bytes_) return false;
    sync = (sync << 8) | map_[p++];
  }
  const int64_t skipped = p - 4 - pos_;
  if (file_bytes_ - p < kHeaderBytes) return false;
  *utime = static_cast<int64_t>(bigEndian(map_ + p + 8, 8));
  const auto channel_len = static_cast<int32_t>(bigEndian(map_ + p + 16, 4));
  const auto data_len = static_cast<int32_t>(bigEndian(map_ + p + 20, 4));
  p += kHeaderBytes;
  if (channel_len <= 0 || channel_len >= 1000 || data_len < 0) return false;
  if (file_bytes_ - p < static_cast<int64_t>(channel_len) + data_len) return false;
  *channel = std::string_view(reinterpret_cast<const char*>(map_ + p), static_cast<size_t>(channel_len));
  *data = map_ + p + channel_len;
  *size = data_len;
  pos_ = p + channel_len + data_len;
  skipped_bytes_ += skipped;
  return true;
}

std::optional<LogEvent> LogSource::next() {
  while (!done_) {
    int64_t utime = 0, size = 0;
    std::string_view channel;
    const uint8_t* data = nullptr;
    if (!readEvent(&utime, &channel, &data, &size)) {
      done_ = true;
      trailing_bytes_ = file_bytes_ - pos_;
      break;
    }
    if (first_utime_ < 0) first_utime_ = utime;
    const double t = (utime - first_utime_) * 1e-6;
    if (t < options_.start_s) continue;
    if (options_.duration_s > 0.0 && t > options_.start_s + options_.duration_s) {
      done_ = true;
      break;
    }
    std::string name(channel);
    auto match = matches_.find(name);
    if (match == matches_.end()) match = matches_.emplace(name, std::regex_match(name, pattern_)).first;
    if (!match->second) continue;
    LogEvent out;
    out.utime = utime;
    out.channel = std::move(name);
    out.data.assign(data, data + size);
    return out;
  }
  return std::nullopt;
}

}  // namespace livo::playback
