#include "livo/latency_stats.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <sys/resource.h>

namespace livo {

namespace {
constexpr double kMinSeconds = 1e-6;
const double kLogStep = std::log(1.01);
}  // namespace

int LatencyStats::binOf(double seconds) {
  if (!(seconds > kMinSeconds)) return 0;
  const int b = static_cast<int>(std::log(seconds / kMinSeconds) / kLogStep);
  return std::min(b, kBins - 1);
}

double LatencyStats::binCentre(int bin) { return kMinSeconds * std::exp((bin + 0.5) * kLogStep); }

void LatencyStats::add(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0) seconds = 0.0;
  ++bins_[binOf(seconds)];
  ++count_;
  sum_s_ += seconds;
  max_s_ = std::max(max_s_, seconds);
}

double LatencyStats::quantileMs(double q) const {
  if (count_ == 0) return 0.0;
  const int64_t rank = std::min<int64_t>(count_ - 1, static_cast<int64_t>(std::floor(q * (count_ - 1) + 0.5)));
  int64_t seen = 0;
  for (int b = 0; b < kBins; ++b) {
    seen += bins_[b];
    if (seen > rank) return std::min(binCentre(b), max_s_) * 1e3;
  }
  return max_s_ * 1e3;
}

void LatencyStats::merge(const LatencyStats& other) {
  for (int b = 0; b < kBins; ++b) bins_[b] += other.bins_[b];
  count_ += other.count_;
  sum_s_ += other.sum_s_;
  max_s_ = std::max(max_s_, other.max_s_);
}

namespace {
double readStatusKb(const char* key) {
  FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return 0.0;
  char line[256];
  double kb = 0.0;
  const size_t n = std::strlen(key);
  while (std::fgets(line, sizeof(line), f)) {
    if (std::strncmp(line, key, n) == 0) {
      kb = std::atof(line + n);
      break;
    }
  }
  std::fclose(f);
  return kb;
}
}  // namespace

double peakRssMb() { return readStatusKb("VmHWM:") / 1024.0; }
double cpuSeconds() {
  rusage u{};
  if (getrusage(RUSAGE_SELF, &u) != 0) return 0.0;
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + (u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-6;
}
double currentRssMb() { return readStatusKb("VmRSS:") / 1024.0; }

}  // namespace livo
