// Summary statistics of a list of errors, defined as evo (numpy) defines them.
#pragma once

#include <cstddef>
#include <vector>

namespace livo::evaluate {

struct ErrorStatistics {
  size_t count = 0;
  double rmse = 0.0;  // sqrt(mean(e^2))
  double mean = 0.0;
  double median = 0.0;  // mean of the two middle values for an even count
  double std = 0.0;     // population standard deviation (numpy's ddof = 0)
  double min = 0.0;
  double max = 0.0;
  double sse = 0.0;  // sum of squares
};

/// All zero with count 0 for an empty list.
ErrorStatistics summarizeErrors(const std::vector<double>& errors);

}  // namespace livo::evaluate
