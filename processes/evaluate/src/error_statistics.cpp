#include "livo/evaluate/error_statistics.hpp"

#include <algorithm>
#include <cmath>

namespace livo::evaluate {

ErrorStatistics summarizeErrors(const std::vector<double>& errors) {
  ErrorStatistics s;
  s.count = errors.size();
  if (errors.empty()) return s;
  const double n = static_cast<double>(errors.size());
  double sum = 0.0;
  s.min = s.max = errors.front();
  for (double e : errors) {
    sum += e;
    s.sse += e * e;
    s.min = std::min(s.min, e);
    s.max = std::max(s.max, e);
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(s.sse / n);
  double var = 0.0;
  for (double e : errors) var += (e - s.mean) * (e - s.mean);
  s.std = std::sqrt(var / n);

  std::vector<double> sorted = errors;
  const size_t mid = sorted.size() / 2;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(mid), sorted.end());
  s.median = sorted[mid];
  if (sorted.size() % 2 == 0) {
    const double lower = *std::max_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(mid));
    s.median = 0.5 * (lower + s.median);
  }
  return s;
}

}  // namespace livo::evaluate
