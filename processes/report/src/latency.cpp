#include "livo/report/latency.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "livo/text_format.hpp"

namespace livo::report {

namespace {
// The tab-separated fields of a line of `path` (line `number`), exactly `count` of them.
std::vector<std::string> fields(const std::string& line, size_t count, const std::string& path, int number) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  for (std::string f; std::getline(ss, f, '\t');) out.push_back(f);
  if (out.size() != count)
    throw std::runtime_error(path + ":" + std::to_string(number) + ": expected " + std::to_string(count) +
                             " tab-separated fields, got " + std::to_string(out.size()));
  return out;
}

int64_t integer(const std::string& text, const std::string& path, int number) {
  size_t used = 0;
  int64_t v = 0;
  try {
    v = std::stoll(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size())
    throw std::runtime_error(path + ":" + std::to_string(number) + ": '" + text + "' is not a whole number");
  return v;
}

// Calls `row` with the fields of every line that is not empty or a comment.
template <class Row>
void readTsv(const std::string& path, size_t count, Row row) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot read");
  std::string line;
  for (int number = 1; std::getline(f, line); ++number)
    if (!line.empty() && line[0] != '#') row(fields(line, count, path, number), number);
}

bool isSensorType(const std::string& type) {
  return type == "livo.imu_t" || type == "livo.point_cloud_t" || type == "livo.image_t" ||
         type == "livo.wheel_odometry_t" || type == "livo.pose_t";
}

double ms(int64_t us) { return us * 1e-3; }

// Sensor stamps to wall time, from the sensor inputs' arrivals at the recorder.
class SensorClock {
 public:
  explicit SensorClock(const std::vector<Arrival>& arrivals) {
    for (const Arrival& a : arrivals) {
      if (a.utime < 0) continue;
      if (a.type == "livo.imu_t") imu_.push_back(a);
      if (a.type == "livo.point_cloud_t") sweeps_.push_back(a);
      if (a.type == "livo.image_t") images_.push_back(a);
      if (isSensorType(a.type)) {
        sensor_channels_.insert(a.channel);
        sensor_ends_.emplace(std::make_pair(a.channel, a.utime), a.end_utime);
      }
    }
    const auto by = [](auto key) { return [key](const Arrival& x, const Arrival& y) { return key(x) < key(y); }; };
    std::stable_sort(imu_.begin(), imu_.end(), by([](const Arrival& a) { return a.utime; }));
    std::stable_sort(sweeps_.begin(), sweeps_.end(), by([](const Arrival& a) { return a.end_utime; }));
    std::stable_sort(images_.begin(), images_.end(), by([](const Arrival& a) { return a.utime; }));
    image_tolerance_us_ = imageTolerance();
  }

  bool isSensor(const std::string& channel) const { return sensor_channels_.count(channel) > 0; }

  // The sensor time a message on `channel` stamped `utime` covers up to (a sweep's end), if seen.
  std::optional<int64_t> sensorEnd(const std::string& channel, int64_t utime) const {
    auto it = sensor_ends_.find({channel, utime});
    if (it == sensor_ends_.end()) return {};
    return it->second;
  }

  // The wall time the sweep ending at `end` was complete: its message had arrived and so had the
  // IMU sample of its end (the first at or after it, less the difference); none without its sweep.
  std::optional<int64_t> sweepEnd(int64_t end) const {
    const Arrival* s = nearest(sweeps_, end, [](const Arrival& a) { return a.end_utime; });
    if (!s || std::llabs(s->end_utime - end) > std::max<int64_t>(1000, (s->end_utime - s->utime) / 2)) return {};
    int64_t due = s->arrival_us;
    auto imu = std::lower_bound(imu_.begin(), imu_.end(), end, [](const Arrival& a, int64_t t) { return a.utime < t; });
    if (imu != imu_.end()) due = std::max(due, imu->arrival_us - (imu->utime - end));
    return due;
  }

  // The arrival of the image stamped nearest `stamp` (within half the image period).
  std::optional<int64_t> image(int64_t stamp) const {
    const Arrival* i = nearest(images_, stamp, [](const Arrival& a) { return a.utime; });
    if (!i || std::llabs(i->utime - stamp) > image_tolerance_us_) return {};
    return i->arrival_us;
  }

  // How far `stamp` is from the nearest sweep end and the nearest image (for kScanOrImage).
  int64_t sweepDistance(int64_t stamp) const {
    return distance(sweeps_, stamp, [](const Arrival& a) { return a.end_utime; });
  }
  int64_t imageDistance(int64_t stamp) const {
    return distance(images_, stamp, [](const Arrival& a) { return a.utime; });
  }

 private:
  template <class Key>
  static const Arrival* nearest(const std::vector<Arrival>& v, int64_t t, Key key) {
    auto it = std::lower_bound(v.begin(), v.end(), t, [&](const Arrival& a, int64_t x) { return key(a) < x; });
    const Arrival* best = it != v.end() ? &*it : nullptr;
    if (it != v.begin() && (!best || t - key(*std::prev(it)) <= key(*best) - t)) best = &*std::prev(it);
    return best;
  }
  template <class Key>
  static int64_t distance(const std::vector<Arrival>& v, int64_t t, Key key) {
    const Arrival* a = nearest(v, t, key);
    return a ? std::llabs(key(*a) - t) : INT64_MAX;
  }
  // half the median interval between image stamps; 25 ms with fewer than two images
  int64_t imageTolerance() const {
    std::vector<double> gaps;
    for (size_t i = 1; i < images_.size(); ++i)
      if (images_[i].utime > images_[i - 1].utime) gaps.push_back(images_[i].utime - images_[i - 1].utime);
    return gaps.empty() ? 25000 : static_cast<int64_t>(nearestRankPercentile(gaps, 0.5) / 2);
  }

  std::vector<Arrival> imu_, sweeps_, images_;
  std::set<std::string> sensor_channels_;
  std::map<std::pair<std::string, int64_t>, int64_t> sensor_ends_;  // (channel, utime) -> end_utime
  int64_t image_tolerance_us_ = 25000;
};

std::optional<int64_t> dueTime(const SensorClock& clock, LatencyReference reference, int64_t stamp) {
  switch (reference) {
    case LatencyReference::kSweepEnd: return clock.sweepEnd(stamp);
    case LatencyReference::kImage: return clock.image(stamp);
    case LatencyReference::kScanOrImage:
      return clock.sweepDistance(stamp) <= clock.imageDistance(stamp) ? clock.sweepEnd(stamp) : clock.image(stamp);
  }
  return {};
}

// The parts of one message's latency from its trace line (due: the stamp's wall time; arrival:
// the message at the recorder).
LatencyParts partsOf(const PublishTrace& t, int64_t due, int64_t arrival, const SensorClock& clock) {
  LatencyParts p;
  const double waited = ms(t.trigger_recv_us - due);
  if (!clock.isSensor(t.trigger_channel)) {
    p.handoff_ms = waited;
  } else if (const auto end = clock.sensorEnd(t.trigger_channel, t.trigger_utime)) {
    // the sensor time the output needed past its stamp (lio: the IMU sample past the sweep end),
    // and how much later than that the data came (a driver's or the replay's delay)
    p.sensors_ms = std::clamp(ms(*end - t.utime), 0.0, std::max(waited, 0.0));
    p.late_sensors_ms = waited - p.sensors_ms;
  } else {
    p.sensors_ms = waited;
  }
  p.queueing_ms = ms(t.start_us - t.trigger_recv_us);
  p.processing_ms = ms(t.publish_us - t.start_us);
  p.delivery_ms = ms(arrival - t.publish_us);
  return p;
}

void accumulate(const LatencyParts& p, double weight, LatencyParts* sum) {
  sum->sensors_ms += weight * p.sensors_ms;
  sum->late_sensors_ms += weight * p.late_sensors_ms;
  sum->handoff_ms += weight * p.handoff_ms;
  sum->queueing_ms += weight * p.queueing_ms;
  sum->processing_ms += weight * p.processing_ms;
  sum->delivery_ms += weight * p.delivery_ms;
}

// Each output's trace lines by stamp, in publication order (chunks of one stamp follow each other).
using TraceQueues = std::map<int64_t, std::deque<const PublishTrace*>>;

// The percentiles and the mean parts, over all traced messages and over the slowest 1 %.
void summarise(const std::vector<std::optional<LatencyParts>>& parts, ChannelLatency* c) {
  c->messages = static_cast<int64_t>(c->latencies_ms.size());
  if (c->latencies_ms.empty()) return;
  c->p50_ms = nearestRankPercentile(c->latencies_ms, 0.5);
  c->p99_ms = nearestRankPercentile(c->latencies_ms, 0.99);
  c->max_ms = *std::max_element(c->latencies_ms.begin(), c->latencies_ms.end());
  LatencyParts all, tail;
  int64_t slow = 0;
  for (size_t i = 0; i < parts.size(); ++i) {
    if (!parts[i]) continue;
    ++c->traced;
    accumulate(*parts[i], 1.0, &all);
    if (c->latencies_ms[i] >= c->p99_ms) {
      ++slow;
      accumulate(*parts[i], 1.0, &tail);
    }
  }
  if (c->traced > 0) accumulate(all, 1.0 / c->traced, &c->mean);
  if (slow > 0) accumulate(tail, 1.0 / slow, &c->slowest);
}

ChannelLatency channelLatency(const LatencySpec& spec, const std::vector<Arrival>& arrivals, const SensorClock& clock,
                              TraceQueues traces) {
  ChannelLatency c;
  c.channel = spec.channel;
  c.reference = spec.reference;
  c.publisher = spec.publisher;
  std::map<std::string, int64_t> publishers;
  std::vector<std::optional<LatencyParts>> parts;
  for (const Arrival& a : arrivals) {
    if (a.channel != spec.channel) continue;
    const PublishTrace* trace = nullptr;
    if (auto q = traces.find(a.utime); q != traces.end() && !q->second.empty()) {
      trace = q->second.front();
      q->second.pop_front();
      ++publishers[trace->process];
    }
    const std::optional<int64_t> due = a.utime < 0 ? std::nullopt : dueTime(clock, spec.reference, a.utime);
    if (!due) {
      ++c.unmatched;
      continue;
    }
    c.latencies_ms.push_back(ms(a.arrival_us - *due));
    parts.push_back(std::nullopt);
    if (trace && trace->trigger_channel != "-") {
      parts.back() = partsOf(*trace, *due, a.arrival_us, clock);
      if (!clock.isSensor(trace->trigger_channel)) ++c.handoffs[trace->trigger_channel];
    }
  }
  if (!publishers.empty())
    c.publisher = std::max_element(publishers.begin(), publishers.end(), [](const auto& x, const auto& y) {
                    return x.second < y.second;
                  })->first;
  summarise(parts, &c);
  return c;
}

const char* referenceName(LatencyReference r) {
  switch (r) {
    case LatencyReference::kSweepEnd: return "sweep end";
    case LatencyReference::kImage: return "image stamp";
    case LatencyReference::kScanOrImage: return "scan or image";
  }
  return "?";
}

nlohmann::json partsJson(const LatencyParts& p) {
  return {{"waiting_for_sensors", p.sensors_ms}, {"sensor_data_late", p.late_sensors_ms},
          {"waiting_for_handoff", p.handoff_ms}, {"queueing", p.queueing_ms},
          {"processing", p.processing_ms},       {"delivery", p.delivery_ms}};
}

std::string fixed(double v) { return std::isfinite(v) ? formatFixed(v, 1) : "n/a"; }

// "mean / slowest" of one part, ms
std::string meanAndSlowest(const nlohmann::json& where, const char* part) {
  const auto get = [&](const char* which) {
    return where.contains(which) && where[which].contains(part) ? where[which][part].get<double>() : std::nan("");
  };
  return fixed(get("mean")) + " / " + fixed(get("slowest_1pct"));
}
}  // namespace

std::vector<Arrival> readArrivals(const std::string& path) {
  std::vector<Arrival> out;
  readTsv(path, 5, [&](const std::vector<std::string>& f, int n) {
    out.push_back({f[0], f[1], integer(f[2], path, n), integer(f[3], path, n), integer(f[4], path, n)});
  });
  return out;
}

std::vector<PublishTrace> readPublishTraces(const std::string& path, const std::string& process) {
  std::vector<PublishTrace> out;
  readTsv(path, 7, [&](const std::vector<std::string>& f, int n) {
    out.push_back({process, f[0], integer(f[1], path, n), f[2], integer(f[3], path, n), integer(f[4], path, n),
                   integer(f[5], path, n), integer(f[6], path, n)});
  });
  return out;
}

std::vector<PublishTrace> readPublishTraceDir(const std::string& dir) {
  const std::string suffix = ".trace.tsv";
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
      files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  std::vector<PublishTrace> out;
  for (const auto& f : files) {
    const std::string name = f.filename().string();
    for (auto& t : readPublishTraces(f.string(), name.substr(0, name.size() - suffix.size())))
      out.push_back(std::move(t));
  }
  return out;
}

std::vector<LatencySpec> defaultLatencySpecs(const std::string& odometry, const std::string& posterior,
                                             const std::string& colored_cloud) {
  return {{odometry, LatencyReference::kSweepEnd, "lio"},
          {posterior, LatencyReference::kImage, "vio"},
          {colored_cloud, LatencyReference::kScanOrImage, "colour"}};
}

double nearestRankPercentile(std::vector<double> values, double q) {
  if (values.empty()) throw std::invalid_argument("nearestRankPercentile: no values");
  if (!(q > 0.0 && q <= 1.0)) throw std::invalid_argument("nearestRankPercentile: q must be in (0, 1]");
  const size_t rank = static_cast<size_t>(std::ceil(q * static_cast<double>(values.size()) - 1e-9));
  std::nth_element(values.begin(), values.begin() + (rank - 1), values.end());
  return values[rank - 1];
}

std::vector<ChannelLatency> computeLatency(const std::vector<Arrival>& arrivals,
                                           const std::vector<PublishTrace>& traces,
                                           const std::vector<LatencySpec>& specs) {
  const SensorClock clock(arrivals);
  std::vector<ChannelLatency> out;
  for (const LatencySpec& spec : specs) {
    TraceQueues queues;
    for (const PublishTrace& t : traces)
      if (t.channel == spec.channel) queues[t.utime].push_back(&t);
    ChannelLatency c = channelLatency(spec, arrivals, clock, std::move(queues));
    if (c.messages + c.unmatched > 0) out.push_back(std::move(c));
  }
  return out;
}

nlohmann::json latencyJson(const ChannelLatency& c) {
  nlohmann::json handoffs = nlohmann::json::object();
  for (const auto& [channel, n] : c.handoffs) handoffs[channel] = n;
  return {{"from", referenceName(c.reference)},
          {"messages", c.messages},
          {"unmatched", c.unmatched},
          {"p50_ms", c.p50_ms},
          {"p99_ms", c.p99_ms},
          {"max_ms", c.max_ms},
          {"where_ms", {{"traced", c.traced}, {"mean", partsJson(c.mean)}, {"slowest_1pct", partsJson(c.slowest)}}},
          {"handoffs", handoffs}};
}

void addLatency(const std::vector<ChannelLatency>& channels, nlohmann::json* timing) {
  for (const ChannelLatency& c : channels) (*timing)[c.publisher]["latency"][c.channel] = latencyJson(c);
}

std::string latencyMarkdown(const nlohmann::json& timing) {
  std::ostringstream rows, parts;
  for (const auto& [process, p] : timing.items()) {
    if (!p.is_object() || !p.contains("latency")) continue;
    for (const auto& [channel, l] : p["latency"].items()) {
      rows << "| " << channel << " | " << process << " | " << l.value("from", std::string()) << " | "
           << l.value("messages", 0) << " | " << fixed(l.value("p50_ms", 0.0)) << " | " << fixed(l.value("p99_ms", 0.0))
           << " | " << fixed(l.value("max_ms", 0.0)) << " |\n";
      const nlohmann::json& w = l["where_ms"];
      std::string handoff = meanAndSlowest(w, "waiting_for_handoff");
      std::string names;
      const nlohmann::json handoffs = l.value("handoffs", nlohmann::json::object());
      for (const auto& [h, n] : handoffs.items())
        names += (names.empty() ? "" : ", ") + h + " " + std::to_string(n.get<int64_t>()) + "x";
      if (!names.empty()) handoff += " (" + names + ")";
      parts << "| " << channel << " | " << meanAndSlowest(w, "waiting_for_sensors") << " | "
            << meanAndSlowest(w, "sensor_data_late") << " | " << handoff << " | " << meanAndSlowest(w, "queueing")
            << " | " << meanAndSlowest(w, "processing") << " | " << meanAndSlowest(w, "delivery") << " |\n";
    }
  }
  if (rows.str().empty()) return "";
  std::ostringstream md;
  md << "## Latency\n\n"
     << "From each output's sensor stamp (its data complete at the recorder) to its arrival at the recorder "
        "(processes/report/README.md, \"Latency\"); percentiles by nearest rank.\n\n"
     << "| output | process | from | messages | p50 ms | p99 ms | max ms |\n"
     << "| --- | --- | --- | --- | --- | --- | --- |\n"
     << rows.str() << "\n"
     << "Where the time goes, ms (mean over all messages / over the slowest 1 %):\n\n"
     << "| output | waiting for sensor data | sensor data late | waiting for a hand-off | queueing | processing | "
        "delivery |\n"
     << "| --- | --- | --- | --- | --- | --- | --- |\n"
     << parts.str() << "\n";
  return md.str();
}

}  // namespace livo::report
