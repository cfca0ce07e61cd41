#include "livo/chi_square.hpp"

#include <cmath>
#include <stdexcept>

namespace livo {

namespace {
// P(a, x) by its power series (x < a + 1) or 1 - Q(a, x) by Lentz's continued fraction.
double regularisedLowerGamma(double a, double x) {
  if (x <= 0.0) return 0.0;
  const double log_prefix = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 1000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < 1e-16 * std::abs(sum)) break;
    }
    return sum * std::exp(log_prefix);
  }
  constexpr double tiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int n = 1; n < 1000; ++n) {
    const double an = -n * (n - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-16) break;
  }
  return 1.0 - std::exp(log_prefix) * h;
}
}  // namespace

double chiSquareCdf(double x, int k) {
  if (k < 1) throw std::invalid_argument("chiSquareCdf: k must be >= 1");
  return regularisedLowerGamma(0.5 * k, 0.5 * x);
}

double chiSquareQuantile(double p, int k) {
  if (!(p > 0.0 && p < 1.0) || k < 1) throw std::invalid_argument("chiSquareQuantile: need p in (0, 1), k >= 1");
  double lo = 0.0, hi = k + 10.0;
  while (chiSquareCdf(hi, k) < p) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (chiSquareCdf(mid, k) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace livo
