#include "livo/sensor_watch/gap_watch.hpp"

#include <stdexcept>

#include "livo/text_format.hpp"

namespace livo::sensor_watch {

GapWatch::GapWatch(const std::vector<std::string>& channels, double gap_s) : gap_s_(gap_s) {
  if (channels.empty()) throw std::invalid_argument("no channel to watch");
  if (!(gap_s > 0.0)) throw std::invalid_argument("the gap must be longer than 0 s, not " + std::to_string(gap_s));
  for (const auto& c : channels) channels_[c];
}

std::optional<SensorGap> GapWatch::arrived(const std::string& channel, double now_s, int64_t utime) {
  auto it = channels_.find(channel);
  if (it == channels_.end()) return std::nullopt;
  Channel& c = it->second;
  std::optional<SensorGap> gap;
  if (c.heard && now_s - c.last_s >= gap_s_)
    gap = SensorGap{channel, c.last_s, now_s, false, false, c.last_stamp, utime};
  c.heard = true;
  c.reported = false;
  c.last_s = now_s;
  c.last_stamp = utime;
  return gap;
}

std::vector<SensorGap> GapWatch::newlySilent(double now_s) {
  std::vector<SensorGap> out;
  for (auto& [name, c] : channels_) {
    if (!c.heard || c.reported || now_s - c.last_s < gap_s_) continue;
    c.reported = true;
    out.push_back({name, c.last_s, now_s, true, false, c.last_stamp, 0});
  }
  return out;
}

std::vector<SensorGap> GapWatch::finish(double now_s) const {
  std::vector<SensorGap> out;
  for (const auto& [name, c] : channels_) {
    if (!c.heard)
      out.push_back({name, 0.0, now_s, true, true, 0, 0});
    else if (now_s - c.last_s >= gap_s_)
      out.push_back({name, c.last_s, now_s, true, false, c.last_stamp, 0});
  }
  return out;
}

void writeGapLine(std::ostream& os, const SensorGap& gap) {
  const auto stamp = [](int64_t utime) { return utime > 0 ? formatFixed(utime * 1e-6, 6) : std::string("-"); };
  os << gap.channel << '\t' << formatFixed(gap.from_s, 3) << '\t' << formatFixed(gap.to_s, 3) << '\t'
     << formatFixed(gap.length(), 3) << '\t'
     << (gap.never  ? "never"
         : gap.open ? "open"
                    : "back")
     << '\t' << stamp(gap.stamp_before) << '\t' << stamp(gap.stamp_after) << '\n';
}

}  // namespace livo::sensor_watch
