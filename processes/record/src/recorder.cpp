#include "livo/record/recorder.hpp"

#include <cmath>
#include <cstring>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>

#include "livo/message_registry.hpp"

namespace livo::record {

namespace {
// Big-endian fields of an encoded LCM message.
bool readBig(const uint8_t* data, int size, int offset, int bytes, uint64_t* out) {
  if (offset < 0 || offset + bytes > size) return false;
  *out = 0;
  for (int i = 0; i < bytes; ++i) *out = (*out << 8) | data[offset + i];
  return true;
}

// A point_cloud_t's sweep_duration, read from its header (utime, frame, pattern, num_rings, then
// it) without decoding the points.
bool sweepDuration(const void* data, int size, double* seconds) {
  const auto* b = static_cast<const uint8_t*>(data);
  uint64_t frame_len = 0, bits = 0;
  if (!readBig(b, size, 16, 4, &frame_len) || frame_len > static_cast<uint64_t>(size)) return false;
  if (!readBig(b, size, 20 + static_cast<int>(frame_len) + 1 + 2, 4, &bits)) return false;
  const auto raw = static_cast<uint32_t>(bits);
  float f = 0.0f;
  std::memcpy(&f, &raw, sizeof f);
  *seconds = f;
  return std::isfinite(f) && f >= 0.0f;
}
}  // namespace

std::string arrivalHeader() { return "# channel\ttype\tutime\tend_utime\tarrival_us\n"; }

std::string arrivalLine(const std::string& channel, const void* data, int size, int64_t arrival_us) {
  const MessageType* type = identifyMessage(data, size);
  int64_t utime = -1;
  if (!messageUtime(data, size, &utime)) utime = -1;
  int64_t end = utime;
  double duration = 0.0;
  if (type && type->name == "livo.point_cloud_t" && utime >= 0 && sweepDuration(data, size, &duration))
    end = utime + static_cast<int64_t>(std::llround(duration * 1e6));
  return channel + "\t" + (type ? type->name : std::string("-")) + "\t" + std::to_string(utime) + "\t" +
         std::to_string(end) + "\t" + std::to_string(arrival_us) + "\n";
}

ArrivalLog::ArrivalLog(lcm::LCM& lcm, const std::string& path, std::string skip)
    : lcm_(lcm), skip_(std::move(skip)), file_(std::fopen(path.c_str(), "a")) {
  if (!file_) throw std::runtime_error(path + ": cannot write");
  if (std::ftell(file_) == 0) std::fputs(arrivalHeader().c_str(), file_);
  sub_ = lcm_.subscribeFunction(".*", &ArrivalLog::onMessage, this);
}

ArrivalLog::~ArrivalLog() {
  if (sub_) lcm_.unsubscribe(sub_);
  if (file_) std::fclose(file_);
}

void ArrivalLog::onMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel, ArrivalLog* self) {
  if (channel == self->skip_) return;
  const std::string line = arrivalLine(channel, rbuf->data, static_cast<int>(rbuf->data_size), rbuf->recv_utime);
  std::fputs(line.c_str(), self->file_);
  ++self->written_;
}

void ArrivalLog::flush() { std::fflush(file_); }

ArrivalThread::ArrivalThread(const std::string& lcm_url, const std::string& path)
    : lcm_(makeLcm(lcm_url)), log_(std::make_unique<ArrivalLog>(*lcm_, path)) {
  thread_ = std::thread([this] {
    while (!stop_.load()) lcm_->handleTimeout(100);
  });
}

ArrivalThread::~ArrivalThread() {
  stop_.store(true);
  thread_.join();
  log_->flush();
}

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
