// Bounded-memory statistics of processing times: a log-spaced histogram (1 % bins from 1 µs to
// 100 s) gives median and p90 to within 1 %, the maximum is exact.
#pragma once

#include <array>
#include <cstdint>

namespace livo {

class LatencyStats {
 public:
  void add(double seconds);
  int64_t count() const { return count_; }
  double maxMs() const { return max_s_ * 1e3; }
  double meanMs() const { return count_ ? sum_s_ / count_ * 1e3 : 0.0; }
  /// q in [0, 1]; 0 when empty.
  double quantileMs(double q) const;
  double medianMs() const { return quantileMs(0.5); }
  double p90Ms() const { return quantileMs(0.9); }
  void merge(const LatencyStats& other);

 private:
  static constexpr int kBins = 1860;  // ceil(log(1e8) / log(1.01))
  static int binOf(double seconds);
  static double binCentre(int bin);

  std::array<uint32_t, kBins> bins_{};
  int64_t count_ = 0;
  double sum_s_ = 0.0;
  double max_s_ = 0.0;
};

/// Peak resident set size of this process (VmHWM), MB; 0 if unknown.
double peakRssMb();
/// CPU time this process has used so far, user plus system (getrusage), in seconds.
double cpuSeconds();
/// Current resident set size (VmRSS), MB; 0 if unknown.
double currentRssMb();

}  // namespace livo
