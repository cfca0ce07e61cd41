// Source stamps to the log's int64 microseconds.
#pragma once

#include <cmath>
#include <cstdint>

namespace livo::import {

/// Nanoseconds -> microseconds, rounded to nearest (halves away from zero).
inline int64_t nsToUtime(int64_t ns) { return ns >= 0 ? (ns + 500) / 1000 : -((-ns + 500) / 1000); }

/// Seconds (float64, as TUM files and KITTI timestamp files give them) -> microseconds, rounded.
inline int64_t secondsToUtime(double s) { return static_cast<int64_t>(std::llround(s * 1e6)); }

}  // namespace livo::import
