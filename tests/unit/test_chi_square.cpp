// The chi-square distribution of the filters' consistency gates: the quantile against printed table
// values, the CDF against closed forms, and each as the other's inverse.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "livo/chi_square.hpp"

using namespace livo;

TEST(ChiSquare, QuantileMatchesTableValues) {
  // (p, k, x) from the standard table (NIST/SEMATECH e-Handbook 1.3.6.7.4), three decimals
  struct Row {
    double p;
    int k;
    double x;
  };
  const Row table[] = {
      {0.95, 1, 3.841},   {0.99, 1, 6.635},    {0.5, 2, 1.386},    {0.95, 2, 5.991},   {0.99, 3, 11.345},
      {0.95, 6, 12.592},  {0.99, 6, 16.812},   {0.999, 6, 22.458}, {0.05, 6, 1.635},   {0.95, 13, 22.362},
      {0.99, 13, 27.688}, {0.999, 13, 34.528}, {0.01, 13, 4.107},  {0.95, 30, 43.773}, {0.99, 100, 135.807},
  };
  for (const Row& r : table) EXPECT_NEAR(chiSquareQuantile(r.p, r.k), r.x, 5e-4) << "p " << r.p << ", k " << r.k;
}

TEST(ChiSquare, CdfMatchesClosedForms) {
  // k = 2: 1 - exp(-x/2); k = 1: erf(sqrt(x/2)); k = 4: 1 - exp(-x/2) (1 + x/2)
  for (const double x : {1e-3, 0.1, 0.7, 1.0, 2.5, 6.0, 15.0, 40.0}) {
    EXPECT_NEAR(chiSquareCdf(x, 2), 1.0 - std::exp(-0.5 * x), 1e-13) << x;
    EXPECT_NEAR(chiSquareCdf(x, 1), std::erf(std::sqrt(0.5 * x)), 1e-13) << x;
    EXPECT_NEAR(chiSquareCdf(x, 4), 1.0 - std::exp(-0.5 * x) * (1.0 + 0.5 * x), 1e-13) << x;
  }
  EXPECT_EQ(chiSquareCdf(0.0, 3), 0.0);
  EXPECT_EQ(chiSquareCdf(-1.0, 3), 0.0);
}

TEST(ChiSquare, CdfIsTheQuantilesInverse) {
  for (const int k : {1, 2, 3, 6, 7, 13, 32, 200}) {
    for (const double p : {1e-4, 0.01, 0.05, 0.3, 0.5, 0.9, 0.95, 0.99, 0.999, 0.99999}) {
      const double x = chiSquareQuantile(p, k);
      EXPECT_NEAR(chiSquareCdf(x, k), p, 1e-10) << "p " << p << ", k " << k;
    }
    // and the quantile of the CDF is the point itself
    for (const double x : {0.5 * k, 1.0 * k, 1.5 * k}) {
      EXPECT_NEAR(chiSquareQuantile(chiSquareCdf(x, k), k), x, 1e-8 * x) << "x " << x << ", k " << k;
    }
  }
  // the CDF is increasing
  double last = 0.0;
  for (double x = 0.05; x < 60.0; x += 0.05) {
    const double c = chiSquareCdf(x, 13);
    EXPECT_GE(c, last) << x;
    last = c;
  }
}

TEST(ChiSquare, RefusesArgumentsOutsideItsDomain) {
  EXPECT_THROW(chiSquareQuantile(0.0, 3), std::invalid_argument);
  EXPECT_THROW(chiSquareQuantile(1.0, 3), std::invalid_argument);
  EXPECT_THROW(chiSquareQuantile(0.5, 0), std::invalid_argument);
  EXPECT_THROW(chiSquareCdf(1.0, 0), std::invalid_argument);
}
