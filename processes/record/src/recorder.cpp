#include "livo/record/recorder.hpp"

#include <stdexcept>

#include <lcm/lcm-cpp.hpp>

#include "livo/message_registry.hpp"

namespace livo::record {

Recorder::Recorder(Node& node, const std::string& out_path, const std::vector<std::string>& channels)
    : node_(node), path_(out_path), log_(std::make_unique<lcm::LogFile>(out_path, "w")) {
  if (!log_->good()) throw std::runtime_error(out_path + ": cannot write");
  for (const auto& ch : channels)
    node_.subscribeRaw(ch, [this, ch](const void* data, int size) { write(ch, data, size); });
}

Recorder::~Recorder() {
  writeHeld();
  flush();
}

void Recorder::write(const std::string& channel, const void* data, int size) {
  int64_t utime = 0;
  if (messageUtime(data, size, &utime) && utime > 0) {
    last_utime_ = utime;
    node_.noteSensorTime(utime);
  }
  if (last_utime_ == 0 && held_.size() < kMaxHeld) {
    const auto* bytes = static_cast<const uint8_t*>(data);
    held_.push_back({channel, std::vector<uint8_t>(bytes, bytes + size)});
    return;
  }
  writeHeld();
  writeEvent(channel, data, size, last_utime_);
}

void Recorder::writeHeld() {
  for (const HeldEvent& e : held_) writeEvent(e.channel, e.data.data(), static_cast<int>(e.data.size()), last_utime_);
  held_.clear();
}

void Recorder::writeEvent(const std::string& channel, const void* data, int size, int64_t timestamp) {
  lcm::LogEvent ev;
  ev.timestamp = timestamp;
  ev.channel = channel;
  ev.datalen = size;
  ev.data = const_cast<void*>(data);
  if (log_->writeEvent(&ev) != 0) {
    node_.error(path_ + ": write failed (disk full?)");
    return;
  }
  ++written_;
}

void Recorder::finish(const std::string& health_channel) {
  writeHeld();
  const health_t h = node_.healthMessage();
  std::vector<uint8_t> buf(h.getEncodedSize());
  h.encode(buf.data(), 0, static_cast<int>(buf.size()));
  lcm::LogEvent ev;
  ev.timestamp = last_utime_;
  ev.channel = health_channel;
  ev.datalen = static_cast<int32_t>(buf.size());
  ev.data = buf.data();
  log_->writeEvent(&ev);
  flush();
}

void Recorder::flush() {
  if (log_) std::fflush(log_->getFilePtr());
}

}  // namespace livo::record
