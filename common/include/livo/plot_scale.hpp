// Pieces of a chart: linear data-to-pixel scales, round tick values and an error colour map (the
// figures of livo-evaluate and livo-report).
#pragma once

#include <string>
#include <vector>

namespace livo {

/// Maps [lo, hi] in data units onto [px_lo, px_hi] pixels (px_hi < px_lo flips, as for a y axis).
struct LinearScale {
  double lo = 0.0, hi = 1.0;
  double px_lo = 0.0, px_hi = 1.0;
  double operator()(double v) const { return px_lo + (v - lo) / (hi - lo) * (px_hi - px_lo); }
};

/// About `target` round values (1, 2 or 5 times a power of ten apart) covering [lo, hi].
std::vector<double> niceTicks(double lo, double hi, int target = 6);

/// [lo, hi] widened to round values around the data (and made non-empty).
void niceRange(double& lo, double& hi, int target = 6);

/// Tick label with no more decimals than the tick step needs.
std::string tickLabel(double v, double step);

/// Colour of a value in [0, 1]: blue (low) through pale yellow to red (high), as "#rrggbb".
std::string errorColour(double t);

}  // namespace livo
