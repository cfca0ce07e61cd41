// A progress line on stderr for long inputs: percentage of the input read, rate and elapsed time,
// redrawn in place on a terminal (at most 4 times a second), one line every 10 s otherwise.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace livo::import {

class ProgressLine {
 public:
  /// `total` in `unit`s ("MB", "files", "packets"); 0 if unknown. Disabled when `enabled` is false.
  ProgressLine(std::string label, double total, std::string unit, bool enabled);
  ~ProgressLine();
  void update(double done);
  /// Clears the in-place line (a summary follows).
  void finish();

 private:
  void draw(double done);
  std::string label_, unit_;
  double total_;
  bool enabled_, tty_, drawn_ = false;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace livo::import
