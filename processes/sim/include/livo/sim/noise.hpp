// Gradient noise on a periodic lattice (tileable), and its fractal sum: the source of every
// procedural texture and height field.
#pragma once

#include <cstdint>

namespace livo::sim {

/// Gradient noise in about [-1, 1], smooth (quintic fade), zero at lattice points, periodic with
/// `period` lattice cells in x and y.
double gradientNoise(double x, double y, int period, uint64_t seed);

/// Sum of `octaves` octaves of gradient noise, each twice the frequency and half the amplitude of
/// the one before; the first has `period` cells per tile. Roughly in [-1, 1].
double fractalNoise(double x, double y, int octaves, int period, uint64_t seed);

}  // namespace livo::sim
