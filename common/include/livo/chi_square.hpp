// The chi-square distribution, for the filters' consistency gates: the probability that a
// chi-square variable with k degrees of freedom stays below x, and its quantile.
#pragma once

namespace livo {

/// P(X <= x) for X ~ chi-square(k), k >= 1 (the regularised lower incomplete gamma P(k/2, x/2)).
double chiSquareCdf(double x, int k);
/// The x with chiSquareCdf(x, k) = p, p in (0, 1): e.g. chiSquareQuantile(0.99, 6) = 16.81.
double chiSquareQuantile(double p, int k);

}  // namespace livo
