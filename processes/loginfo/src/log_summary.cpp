#include "livo/loginfo/log_summary.hpp"

#include <sys/stat.h>
#include <cstdio>
#include <iomanip>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>

#include "livo/message_registry.hpp"

namespace livo::loginfo {

double ChannelSummary::rateHz() const {
  if (count < 2 || last_utime <= first_utime) return 0.0;
  return (count - 1) / ((last_utime - first_utime) * 1e-6);
}

namespace {
std::string typeOf(const void* data, int size) {
  if (const MessageType* t = identifyMessage(data, size)) return t->name;
  if (size < 8) return "unknown (short)";
  const auto* b = static_cast<const uint8_t*>(data);
  std::ostringstream os;
  os << "unknown (0x" << std::hex << std::setfill('0');
  for (int i = 0; i < 8; ++i) os << std::setw(2) << static_cast<int>(b[i]);
  os << ")";
  return os.str();
}

std::string humanBytes(double b) {
  const char* units[] = {"B", "KB", "MB", "GB", "TB"};
  int u = 0;
  while (b >= 1024.0 && u < 4) b /= 1024.0, ++u;
  std::ostringstream os;
  os << std::fixed << std::setprecision(u ? 1 : 0) << b << " " << units[u];
  return os.str();
}
}  // namespace

LogSummary summarizeLog(const std::string& path) {
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) throw std::runtime_error(path + ": no such file");
  lcm::LogFile log(path, "r");
  if (!log.good()) throw std::runtime_error(path + ": cannot open as an LCM log");
  LogSummary s;
  s.path = path;
  s.file_bytes = st.st_size;
  long end_of_last = 0;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    end_of_last = std::ftell(log.getFilePtr());
    ChannelSummary& c = s.channels[ev->channel];
    const std::string type = typeOf(ev->data, ev->datalen);
    if (c.count == 0) {
      c.type = type;
      c.first_utime = ev->timestamp;
    } else {
      if (c.type != type) c.type = "mixed";
      if (ev->timestamp < c.last_utime) ++c.out_of_order;
    }
    c.last_utime = std::max(c.last_utime, ev->timestamp);
    ++c.count;
    c.bytes += ev->datalen;
    if (c.count == 1) c.digest = 14695981039346656037ULL;
    const auto* b = static_cast<const uint8_t*>(ev->data);
    for (int32_t i = 0; i < ev->datalen; ++i) c.digest = (c.digest ^ b[i]) * 1099511628211ULL;
    if (const int64_t bad = countNonFinite(ev->data, ev->datalen); bad > 0) {
      ++c.non_finite_messages;
      c.non_finite_values += bad;
    }
    if (s.events == 0 || ev->timestamp < s.first_utime) s.first_utime = ev->timestamp;
    if (s.events == 0 || ev->timestamp > s.last_utime) s.last_utime = ev->timestamp;
    ++s.events;
  }
  s.trailing_bytes = s.file_bytes - end_of_last;
  return s;
}

void printLogSummary(const LogSummary& s, std::ostream& os, bool with_digest, bool with_non_finite) {
  os << "path:      " << s.path << "\n";
  os << "size:      " << humanBytes(static_cast<double>(s.file_bytes)) << "\n";
  os << std::fixed << std::setprecision(3);
  os << "start:     " << s.first_utime * 1e-6 << " s\n";
  os << "end:       " << s.last_utime * 1e-6 << " s\n";
  os << "duration:  " << s.durationS() << " s\n";
  os << "messages:  " << s.events << "\n";
  if (s.trailing_bytes > 0)
    os << "warning:   " << s.trailing_bytes << " bytes after the last readable event (truncated or corrupt)\n";
  size_t w = 8;
  for (const auto& [name, c] : s.channels) w = std::max(w, name.size());
  size_t tw = 4;
  for (const auto& [name, c] : s.channels) tw = std::max(tw, c.type.size());
  os << "\n"
     << std::left << std::setw(static_cast<int>(w) + 2) << "channel" << std::setw(static_cast<int>(tw) + 2) << "type"
     << std::right << std::setw(10) << "count" << std::setw(11) << "rate Hz" << std::setw(12) << "bytes";
  if (with_digest) os << "  digest";
  if (with_non_finite) os << "  non-finite";
  os << "\n";
  for (const auto& [name, c] : s.channels) {
    os << std::left << std::setw(static_cast<int>(w) + 2) << name << std::setw(static_cast<int>(tw) + 2) << c.type
       << std::right << std::setw(10) << c.count << std::setw(11) << std::setprecision(2) << c.rateHz() << std::setw(12)
       << humanBytes(static_cast<double>(c.bytes));
    if (with_digest)
      os << "  " << std::hex << std::setw(16) << std::setfill('0') << c.digest << std::dec << std::setfill(' ');
    if (with_non_finite) os << "  " << std::setw(10) << c.non_finite_messages;
    if (c.out_of_order) os << "  (" << c.out_of_order << " out of order)";
    os << "\n";
  }
}

}  // namespace livo::loginfo
