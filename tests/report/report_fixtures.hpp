// Shared pieces of the report tests: coloured maps made of planes of points.
#pragma once

#include <array>
#include <cstdint>

#include "livo/coloured_point_files.hpp"

namespace livo_test {

/// Points on a grid `step` apart (at cell centres) over [x0, x1) x [y0, y1) at height z, coloured `rgb`.
inline void addPlane(livo::ColouredPoints* p, double x0, double x1, double y0, double y1, double z, double step,
                     const std::array<uint8_t, 3>& rgb) {
  for (double x = x0 + step / 2; x < x1; x += step)
    for (double y = y0 + step / 2; y < y1; y += step) {
      p->position.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
      p->rgb.push_back(rgb);
    }
}

}  // namespace livo_test
