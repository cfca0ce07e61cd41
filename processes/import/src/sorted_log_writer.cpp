#include "livo/import/sorted_log_writer.hpp"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <queue>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>

namespace livo::import {

SortedLogWriter::SortedLogWriter(std::string path, SortedLogWriterOptions options)
    : path_(std::move(path)), options_(options) {}

SortedLogWriter::~SortedLogWriter() {
  if (!finished_) removeRuns();
}

void SortedLogWriter::addEncoded(const std::string& channel, int64_t utime, std::vector<uint8_t> bytes) {
  buffer_bytes_ += static_cast<int64_t>(bytes.size() + channel.size() + sizeof(Event));
  buffer_.push_back(Event{utime, channel, std::move(bytes)});
  ++counts_[channel];
  if (buffer_bytes_ > options_.max_buffer_bytes) spill();
}

namespace {
void writeEvent(lcm::LogFile& log, int64_t utime, const std::string& channel, const std::vector<uint8_t>& data,
                const std::string& path) {
  lcm::LogEvent ev;
  ev.eventnum = 0;
  ev.timestamp = utime;
  ev.channel = channel;
  ev.datalen = static_cast<int32_t>(data.size());
  ev.data = const_cast<uint8_t*>(data.data());
  if (log.writeEvent(&ev) != 0) throw std::runtime_error(path + ": write failed (disk full?)");
}
}  // namespace

void SortedLogWriter::spill() {
  std::stable_sort(buffer_.begin(), buffer_.end(), [](const Event& a, const Event& b) { return a.utime < b.utime; });
  const std::string run = path_ + ".run" + std::to_string(runs_.size()) + ".tmp";
  {
    lcm::LogFile log(run, "w");
    if (!log.good()) throw std::runtime_error(run + ": cannot create temporary run file");
    for (const Event& e : buffer_) writeEvent(log, e.utime, e.channel, e.data, run);
  }
  runs_.push_back(run);
  buffer_.clear();
  buffer_.shrink_to_fit();
  buffer_bytes_ = 0;
}

void SortedLogWriter::removeRuns() {
  for (const std::string& r : runs_) std::remove(r.c_str());
  runs_.clear();
}

void SortedLogWriter::finish() {
  if (finished_) return;
  std::stable_sort(buffer_.begin(), buffer_.end(), [](const Event& a, const Event& b) { return a.utime < b.utime; });
  lcm::LogFile out(path_, "w");
  if (!out.good()) throw std::runtime_error(path_ + ": cannot create the output log");
  if (runs_.empty()) {
    for (const Event& e : buffer_) writeEvent(out, e.utime, e.channel, e.data, path_);
  } else {
    // k-way merge: runs in spill order, then the in-memory buffer (the newest insertions). Ties go
    // to the lower source index, which keeps insertion order.
    std::vector<std::unique_ptr<lcm::LogFile>> logs;
    for (const std::string& r : runs_) {
      logs.push_back(std::make_unique<lcm::LogFile>(r, "r"));
      if (!logs.back()->good()) throw std::runtime_error(r + ": cannot reopen temporary run file");
    }
    const int memory_source = static_cast<int>(logs.size());
    std::vector<const lcm::LogEvent*> current(logs.size(), nullptr);
    size_t buffer_pos = 0;
    using Head = std::pair<int64_t, int>;  // utime, source
    std::priority_queue<Head, std::vector<Head>, std::greater<Head>> heads;
    for (int i = 0; i < memory_source; ++i)
      if ((current[i] = logs[i]->readNextEvent())) heads.push({current[i]->timestamp, i});
    if (!buffer_.empty()) heads.push({buffer_[0].utime, memory_source});
    std::vector<uint8_t> scratch;
    while (!heads.empty()) {
      const int src = heads.top().second;
      heads.pop();
      if (src == memory_source) {
        const Event& e = buffer_[buffer_pos++];
        writeEvent(out, e.utime, e.channel, e.data, path_);
        if (buffer_pos < buffer_.size()) heads.push({buffer_[buffer_pos].utime, memory_source});
      } else {
        const lcm::LogEvent* ev = current[src];
        scratch.assign(static_cast<const uint8_t*>(ev->data), static_cast<const uint8_t*>(ev->data) + ev->datalen);
        writeEvent(out, ev->timestamp, ev->channel, scratch, path_);
        if ((current[src] = logs[src]->readNextEvent())) heads.push({current[src]->timestamp, src});
      }
    }
  }
  buffer_.clear();
  removeRuns();
  finished_ = true;
}

}  // namespace livo::import
