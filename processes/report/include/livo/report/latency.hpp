// Latency in real-time runs: for every output message, the time from its sensor stamp to its
// publication, and where that time went. Read from two kinds of side files of a run:
//   - livo-record --arrivals: when each message (sensor inputs, hand-offs, outputs) reached the
//     recorder (wall clock, LCM's recv_utime), with its stamp;
//   - LIVO_LATENCY_TRACE (common/node.hpp), one per process: for each message it published, the
//     input whose handler published it, when that input reached the process, when the handler
//     started and when the message went out.
// A sensor stamp becomes a wall time through the arrival of the sensor data that carries it:
// playback publishes a message when its stamp is due, drivers when their data is complete. See
// processes/report/README.md, "Latency".
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace livo::report {

/// One line of livo-record's arrival log.
struct Arrival {
  std::string channel;
  std::string type;        // LCM type name ("livo.imu_t"), "-" if unknown
  int64_t utime = -1;      // the message's stamp, -1 if it has none
  int64_t end_utime = -1;  // a LiDAR sweep's end (utime + sweep_duration); utime for other types
  int64_t arrival_us = 0;  // wall clock, µs
};

/// One line of a process's LIVO_LATENCY_TRACE file.
struct PublishTrace {
  std::string process;  // from the file name
  std::string channel;
  int64_t utime = -1;
  std::string trigger_channel;  // "-": published outside any handler (at shutdown)
  int64_t trigger_utime = -1;
  int64_t trigger_recv_us = 0;  // the input reached the process (LCM's recv_utime)
  int64_t start_us = 0;         // its handler started
  int64_t publish_us = 0;       // this message went out
};

/// Throw std::runtime_error naming the file and line for a malformed line; a missing file throws.
std::vector<Arrival> readArrivals(const std::string& path);
std::vector<PublishTrace> readPublishTraces(const std::string& path, const std::string& process);
/// Every DIR/<process>.trace.tsv (scripts/run_pipeline.sh's names); none: empty.
std::vector<PublishTrace> readPublishTraceDir(const std::string& dir);

/// Which sensor stamp an output answers.
enum class LatencyReference {
  kSweepEnd,    // a LiDAR sweep's end (ODOMETRY, REGISTERED_SCAN)
  kImage,       // an image's stamp (STATE_POSTERIOR)
  kScanOrImage  // whichever of the two the stamp is nearer (COLORED_CLOUD: made on a scan or an image)
};

struct LatencySpec {
  std::string channel;
  LatencyReference reference = LatencyReference::kSweepEnd;
  std::string publisher;  // the process it is filed under when no trace names one
};

/// The default outputs: ODOMETRY (lio), STATE_POSTERIOR (vio), COLORED_CLOUD (colour).
std::vector<LatencySpec> defaultLatencySpecs(const std::string& odometry = "ODOMETRY",
                                             const std::string& posterior = "STATE_POSTERIOR",
                                             const std::string& colored_cloud = "COLORED_CLOUD");

/// Where one message's latency went, ms; the parts add up to its latency.
struct LatencyParts {
  double sensors_ms = 0.0;       // waiting for sensor data: the sensor time the output needed past its
                                 // stamp (the input that set the handler off: its end less the stamp)
  double late_sensors_ms = 0.0;  // that input came later than its sensor time says (driver, replay)
  double handoff_ms = 0.0;       // ... when that input was another process's message (a hand-off)
  double queueing_ms = 0.0;      // that input waited in the process's queue before its handler started
  double processing_ms = 0.0;    // the handler, until this message went out
  double delivery_ms = 0.0;      // from its publication to its arrival at the recorder
};

struct ChannelLatency {
  std::string channel;
  std::string publisher;
  LatencyReference reference = LatencyReference::kSweepEnd;
  int64_t messages = 0;   // with a latency
  int64_t unmatched = 0;  // no sensor input of their stamp was seen (not in the figures)
  int64_t traced = 0;     // of `messages`, those with a trace line (in the parts)
  double p50_ms = 0.0, p99_ms = 0.0, max_ms = 0.0;
  LatencyParts mean;                        // over the traced messages
  LatencyParts slowest;                     // over the traced messages at or above p99
  std::map<std::string, int64_t> handoffs;  // hand-off channel -> messages whose handler it set off
  std::vector<double> latencies_ms;         // per message, in arrival order
};

/// The nearest-rank percentile: the smallest value with at least q of the values at or below it
/// (sorted[ceil(q n) - 1]); q in (0, 1]. Throws std::invalid_argument for no values or q out of range.
double nearestRankPercentile(std::vector<double> values, double q);

/// Latency of every spec's channel that has arrivals; channels with none are left out.
std::vector<ChannelLatency> computeLatency(const std::vector<Arrival>& arrivals,
                                           const std::vector<PublishTrace>& traces,
                                           const std::vector<LatencySpec>& specs);

/// {"from", "messages", "unmatched", "p50_ms", "p99_ms", "max_ms", "where_ms": {"traced", "mean": {...},
/// "slowest_1pct": {...}}, "handoffs": {...}}: timing.json's latency[CHANNEL] under its publisher.
nlohmann::json latencyJson(const ChannelLatency& c);
/// Adds each channel's latencyJson to timing[publisher]["latency"][channel].
void addLatency(const std::vector<ChannelLatency>& channels, nlohmann::json* timing);
/// report.md's "Latency" section from timing.json; empty when no process has a latency object.
std::string latencyMarkdown(const nlohmann::json& timing);

}  // namespace livo::report
