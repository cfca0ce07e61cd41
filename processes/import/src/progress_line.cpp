#include "livo/import/progress_line.hpp"

#include <unistd.h>
#include <cstdio>

namespace livo::import {

ProgressLine::ProgressLine(std::string label, double total, std::string unit, bool enabled)
    : label_(std::move(label)), unit_(std::move(unit)), total_(total), enabled_(enabled), tty_(isatty(2) != 0) {
  start_ = last_ = std::chrono::steady_clock::now();
}

ProgressLine::~ProgressLine() { finish(); }

void ProgressLine::update(double done) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const double since = std::chrono::duration<double>(now - last_).count();
  if (since < (tty_ ? 0.25 : 10.0)) return;
  last_ = now;
  draw(done);
}

void ProgressLine::draw(double done) {
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  char buf[200];
  if (total_ > 0)
    std::snprintf(buf, sizeof(buf), "%s: %5.1f %%  %.1f / %.1f %s  %.1f s", label_.c_str(), 100.0 * done / total_, done,
                  total_, unit_.c_str(), elapsed);
  else
    std::snprintf(buf, sizeof(buf), "%s: %.1f %s  %.1f s", label_.c_str(), done, unit_.c_str(), elapsed);
  std::fprintf(stderr, tty_ ? "\r%-78s" : "%s\n", buf);
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressLine::finish() {
  if (enabled_ && tty_ && drawn_) std::fprintf(stderr, "\r%-78s\r", "");
  drawn_ = false;
}

}  // namespace livo::import
