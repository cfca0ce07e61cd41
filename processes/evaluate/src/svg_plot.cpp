#include "livo/evaluate/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <stdexcept>

#include "livo/plot_scale.hpp"
#include "livo/text_format.hpp"

namespace livo::evaluate {

namespace {

constexpr int kColourLevels = 48;
const char* const kFont = "font-family=\"DejaVu Sans, Arial, sans-serif\"";

std::string fixed1(double v) { return formatFixed(v, 1); }

std::string number(double v, int significant = 4) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*g", significant, v);
  return buf;
}

struct Rect {
  double x, y, w, h;
};

class Svg {
 public:
  std::ostringstream os;

  void text(double x, double y, const std::string& s, int size, const char* anchor = "start", const char* extra = "") {
    os << "<text x=\"" << fixed1(x) << "\" y=\"" << fixed1(y) << "\" font-size=\"" << size << "\" text-anchor=\""
       << anchor << "\" " << kFont << " " << extra << ">" << escapeMarkup(s) << "</text>\n";
  }
  void line(double x0, double y0, double x1, double y1, const std::string& stroke, double width,
            const char* extra = "") {
    os << "<line x1=\"" << fixed1(x0) << "\" y1=\"" << fixed1(y0) << "\" x2=\"" << fixed1(x1) << "\" y2=\""
       << fixed1(y1) << "\" stroke=\"" << stroke << "\" stroke-width=\"" << width << "\" " << extra << "/>\n";
  }
  void dot(double x, double y, double r, const std::string& fill) {
    os << "<circle cx=\"" << fixed1(x) << "\" cy=\"" << fixed1(y) << "\" r=\"" << r << "\" fill=\"" << fill << "\"/>\n";
  }
  void polyline(const std::vector<std::pair<double, double>>& pts, const std::string& stroke, double width,
                const char* extra = "") {
    if (pts.size() < 2) return;
    os << "<polyline fill=\"none\" stroke=\"" << stroke << "\" stroke-width=\"" << width
       << "\" stroke-linejoin=\"round\" stroke-linecap=\"round\" " << extra << " points=\"";
    for (const auto& p : pts) os << fixed1(p.first) << "," << fixed1(p.second) << " ";
    os << "\"/>\n";
  }
};

/// Drops points that move less than `min_px` from the last kept one (the last point is kept).
std::vector<std::pair<double, double>> thin(const std::vector<std::pair<double, double>>& pts, double min_px) {
  std::vector<std::pair<double, double>> out;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (!out.empty() && i + 1 < pts.size() &&
        std::hypot(pts[i].first - out.back().first, pts[i].second - out.back().second) < min_px)
      continue;
    out.push_back(pts[i]);
  }
  return out;
}

constexpr double kMarkSlack_s = 1e-3;  // a pose within this of a span's end is in it (TUM rounding)
constexpr double kLoopSlack_s = 0.25;  // a loop's keyframe is drawn at the pose this near in time

/// The marks on the time axes of the panels, in seconds since the first pair.
struct TimeMarks {
  std::vector<std::pair<double, double>> degenerate, predicted;
  std::vector<double> loops;
};

TimeMarks marksSinceStart(const PlotMarks& m, double t0) {
  TimeMarks out;
  for (const auto& [a, b] : m.degenerate) out.degenerate.emplace_back(a - t0, b - t0);
  for (const auto& [a, b] : m.predicted) out.predicted.emplace_back(a - t0, b - t0);
  for (const auto& l : m.loops) out.loops.push_back(l.time - t0);
  return out;
}

/// Per stamp (in time order), whether it lies in one of the [from, to] spans (which do not overlap).
std::vector<bool> inSpans(const std::vector<double>& stamps, std::vector<std::pair<double, double>> spans) {
  std::sort(spans.begin(), spans.end());
  std::vector<bool> in(stamps.size(), false);
  for (size_t k = 0; k < stamps.size(); ++k) {
    // the last span starting at or before the stamp
    const auto after = std::upper_bound(spans.begin(), spans.end(), stamps[k] + kMarkSlack_s,
                                        [](double t, const std::pair<double, double>& s) { return t < s.first; });
    in[k] = after != spans.begin() && stamps[k] <= std::prev(after)->second + kMarkSlack_s;
  }
  return in;
}

/// The pose whose stamp (in time order) is nearest `t`, or npos when none is within kLoopSlack_s.
size_t nearestPose(const std::vector<double>& stamps, double t) {
  if (!std::isfinite(t) || stamps.empty()) return std::string::npos;
  const size_t hi = static_cast<size_t>(std::lower_bound(stamps.begin(), stamps.end(), t) - stamps.begin());
  size_t best = std::min(hi, stamps.size() - 1);
  if (hi > 0 && std::abs(stamps[hi - 1] - t) <= std::abs(stamps[best] - t)) best = hi - 1;
  return std::abs(stamps[best] - t) <= kLoopSlack_s ? best : std::string::npos;
}

/// A wide translucent stroke along the path where `flagged`, from halfway to the pose before to
/// halfway to the pose after (never across a gap longer than max_step). False if nothing was drawn.
bool overlayRuns(Svg& svg, const std::vector<std::pair<double, double>>& px, const std::vector<double>& stamps,
                 const std::vector<bool>& flagged, double max_step, const char* colour) {
  auto mid = [&](size_t a, size_t b) {
    return std::make_pair(0.5 * (px[a].first + px[b].first), 0.5 * (px[a].second + px[b].second));
  };
  auto joined = [&](size_t a, size_t b) { return std::abs(stamps[b] - stamps[a]) <= max_step; };
  bool drawn = false;
  for (size_t i = 0; i < px.size(); ++i) {
    if (!flagged[i]) continue;
    std::vector<std::pair<double, double>> run;
    if (i > 0 && joined(i - 1, i)) run.push_back(mid(i - 1, i));
    run.push_back(px[i]);
    while (i + 1 < px.size() && flagged[i + 1] && joined(i, i + 1)) run.push_back(px[++i]);
    if (i + 1 < px.size() && joined(i, i + 1)) run.push_back(mid(i, i + 1));
    if (run.size() == 1) run.push_back(run.front());  // a lone pose: a dot (round caps)
    svg.polyline(thin(run, 0.7), colour, 9, "stroke-opacity=\"0.45\"");
    drawn = true;
  }
  return drawn;
}

/// Each loop closure as a dashed line between the poses at its two keyframes' stamps, with a dot at
/// each end. False if none could be placed.
bool loopLines(Svg& svg, const std::vector<std::pair<double, double>>& px, const std::vector<double>& stamps,
               const std::vector<PlotMarks::Loop>& loops) {
  bool drawn = false;
  for (const PlotMarks::Loop& l : loops) {
    const size_t a = nearestPose(stamps, l.from_stamp), b = nearestPose(stamps, l.to_stamp);
    if (a == std::string::npos || b == std::string::npos) continue;
    svg.line(px[a].first, px[a].second, px[b].first, px[b].second, kLoopColour, 1.8, "stroke-dasharray=\"6,3\"");
    for (size_t k : {a, b}) svg.dot(px[k].first, px[k].second, 3.5, kLoopColour);
    drawn = true;
  }
  return drawn;
}

/// Frame, grid, ticks and axis titles of a panel; returns the scales.
std::pair<LinearScale, LinearScale> axes(Svg& svg, const Rect& r, double xlo, double xhi, double ylo, double yhi,
                                         const std::string& xtitle, const std::string& ytitle, int xticks, int yticks) {
  LinearScale sx{xlo, xhi, r.x, r.x + r.w}, sy{ylo, yhi, r.y + r.h, r.y};
  svg.os << "<rect x=\"" << fixed1(r.x) << "\" y=\"" << fixed1(r.y) << "\" width=\"" << fixed1(r.w) << "\" height=\""
         << fixed1(r.h) << "\" fill=\"#ffffff\" stroke=\"#444444\" stroke-width=\"1\"/>\n";
  const auto xt = niceTicks(xlo, xhi, xticks), yt = niceTicks(ylo, yhi, yticks);
  const double xstep = xt.size() > 1 ? xt[1] - xt[0] : 1.0, ystep = yt.size() > 1 ? yt[1] - yt[0] : 1.0;
  for (double v : xt) {
    const double x = sx(v);
    svg.line(x, r.y, x, r.y + r.h, "#e3e3e3", 1);
    svg.line(x, r.y + r.h, x, r.y + r.h + 5, "#444444", 1);
    svg.text(x, r.y + r.h + 20, tickLabel(v, xstep), 13, "middle");
  }
  for (double v : yt) {
    const double y = sy(v);
    svg.line(r.x, y, r.x + r.w, y, "#e3e3e3", 1);
    svg.line(r.x - 5, y, r.x, y, "#444444", 1);
    svg.text(r.x - 8, y + 4.5, tickLabel(v, ystep), 13, "end");
  }
  svg.text(r.x + r.w / 2, r.y + r.h + 42, xtitle, 15, "middle");
  std::ostringstream rot;
  rot << "transform=\"rotate(-90 " << fixed1(r.x - 58) << " " << fixed1(r.y + r.h / 2) << ")\"";
  svg.text(r.x - 58, r.y + r.h / 2, ytitle, 15, "middle", rot.str().c_str());
  return {sx, sy};
}

/// The two axes (a < b) along which the ground truth and the estimate spread most, and their extents.
struct PlanView {
  int a = 0, b = 1;
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
};

PlanView planView(const Evaluation& ev) {
  PlanView v;
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  for (const auto& p : ev.gt_path) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  for (const auto& T : ev.est) lo = lo.cwiseMin(Vec3(T.translation())), hi = hi.cwiseMax(Vec3(T.translation()));
  const Vec3 extent = hi - lo;
  int order[3] = {0, 1, 2};
  std::stable_sort(order, order + 3, [&](int i, int j) { return extent[i] > extent[j]; });
  v.a = std::min(order[0], order[1]), v.b = std::max(order[0], order[1]);
  v.lo = lo, v.hi = hi;
  return v;
}

/// The panel's axes: equal scale on both, the path centred in the area.
std::pair<LinearScale, LinearScale> planAxes(Svg& svg, const Rect& area, const PlanView& v) {
  const char* names[3] = {"x", "y", "z"};
  double xlo = v.lo[v.a], xhi = v.hi[v.a], ylo = v.lo[v.b], yhi = v.hi[v.b];
  niceRange(xlo, xhi, 7);
  niceRange(ylo, yhi, 7);
  const double m_per_px = std::max((xhi - xlo) / area.w, (yhi - ylo) / area.h);
  const double cx = 0.5 * (xlo + xhi), cy = 0.5 * (ylo + yhi);
  xlo = cx - 0.5 * area.w * m_per_px, xhi = cx + 0.5 * area.w * m_per_px;
  ylo = cy - 0.5 * area.h * m_per_px, yhi = cy + 0.5 * area.h * m_per_px;
  return axes(svg, area, xlo, xhi, ylo, yhi, std::string(names[v.a]) + " (m)", std::string(names[v.b]) + " (m)", 7, 7);
}

/// The estimate coloured by its ATE: runs of segments in one colour level become one polyline; no
/// line where it was not tracked (pairs more than max_step apart).
void errorColouredPath(Svg& svg, const std::vector<std::pair<double, double>>& est_px, const Evaluation& ev,
                       double err_lo, double err_hi, double max_step) {
  const double span = err_hi > err_lo ? err_hi - err_lo : 1.0;
  auto level = [&](double e) {
    return std::min(kColourLevels - 1, std::max(0, static_cast<int>((e - err_lo) / span * kColourLevels)));
  };
  std::vector<std::pair<double, double>> run;
  int run_level = -1;
  for (size_t k = 0; k + 1 < ev.est.size(); ++k) {
    if (std::abs(ev.gt_stamps[k + 1] - ev.gt_stamps[k]) > max_step) {  // not tracked in between: no line
      svg.polyline(thin(run, 0.7), errorColour((run_level + 0.5) / kColourLevels), 2.6);
      run.clear();
      run_level = -1;
      continue;
    }
    const int l = level(0.5 * (ev.ate_m[k] + ev.ate_m[k + 1]));
    if (l != run_level) {
      svg.polyline(thin(run, 0.7), errorColour((run_level + 0.5) / kColourLevels), 2.6);
      run = {est_px[k]};
      run_level = l;
    }
    run.push_back(est_px[k + 1]);
  }
  svg.polyline(thin(run, 0.7), errorColour((run_level + 0.5) / kColourLevels), 2.6);
}

/// A circle at the start, a square at the end.
void startAndEnd(Svg& svg, std::pair<double, double> s, std::pair<double, double> e) {
  svg.os << "<circle cx=\"" << fixed1(s.first) << "\" cy=\"" << fixed1(s.second)
         << "\" r=\"6\" fill=\"none\" stroke=\"#000000\" stroke-width=\"2\"/>\n";
  svg.os << "<rect x=\"" << fixed1(e.first - 5) << "\" y=\"" << fixed1(e.second - 5)
         << "\" width=\"10\" height=\"10\" fill=\"none\" stroke=\"#000000\" stroke-width=\"2\"/>\n";
}

/// Legend of the top view: a row per thing drawn, then start and end.
void topViewLegend(Svg& svg, const Rect& area, bool degenerate_drawn, bool predicted_drawn, bool loops_drawn) {
  std::vector<std::pair<std::function<void(double, double)>, std::string>> rows;
  rows.push_back({[&](double x, double y) { svg.line(x, y, x + 30, y, "#555555", 1.6, "stroke-dasharray=\"5,3\""); },
                  "ground truth"});
  rows.push_back({[&](double x, double y) {
                    svg.line(x, y, x + 15, y, errorColour(0.1), 2.6);
                    svg.line(x + 15, y, x + 30, y, errorColour(0.9), 2.6);
                  },
                  "estimate, coloured by ATE"});
  auto overlay = [&](const char* colour) {
    return [&svg, colour](double x, double y) { svg.line(x, y, x + 30, y, colour, 9, "stroke-opacity=\"0.45\""); };
  };
  if (degenerate_drawn) rows.push_back({overlay(kDegenerateColour), "degenerate sweeps"});
  if (predicted_drawn) rows.push_back({overlay(kPredictedColour), "predicted, no LiDAR update"});
  if (loops_drawn)
    rows.push_back({[&](double x, double y) {
                      svg.line(x, y, x + 30, y, kLoopColour, 1.8, "stroke-dasharray=\"6,3\"");
                      svg.dot(x, y, 3.5, kLoopColour);
                      svg.dot(x + 30, y, 3.5, kLoopColour);
                    },
                    "loop closure (its keyframes)"});
  const double lx = area.x + 12, ly = area.y + 14, row_h = 20;
  svg.os << "<rect x=\"" << fixed1(lx - 6) << "\" y=\"" << fixed1(ly - 8) << "\" width=\"250\" height=\""
         << fixed1(row_h * static_cast<double>(rows.size() + 1) + 4) << "\" fill=\"#ffffff\" "
         << "fill-opacity=\"0.85\" stroke=\"#bbbbbb\"/>\n";
  for (size_t i = 0; i < rows.size(); ++i) {
    const double y = ly + 4 + row_h * static_cast<double>(i);
    rows[i].first(lx, y);
    svg.text(lx + 38, y + 5, rows[i].second, 13);
  }
  const double ey = ly + 4 + row_h * static_cast<double>(rows.size());
  svg.os << "<circle cx=\"" << fixed1(lx + 8) << "\" cy=\"" << fixed1(ey)
         << "\" r=\"5\" fill=\"none\" stroke=\"#000\" stroke-width=\"2\"/>\n";
  svg.text(lx + 18, ey + 5, "start", 13);
  svg.os << "<rect x=\"" << fixed1(lx + 64) << "\" y=\"" << fixed1(ey - 5)
         << "\" width=\"10\" height=\"10\" fill=\"none\" stroke=\"#000\" stroke-width=\"2\"/>\n";
  svg.text(lx + 80, ey + 5, "end", 13);
}

/// The paths from above, in the plane they spread most in: the ground truth dashed, the estimate
/// coloured by its ATE over where the estimator was weak, the loop closures, start and end.
void topView(Svg& svg, const Rect& area, const Evaluation& ev, double err_lo, double err_hi, double max_step,
             const PlotMarks& marks) {
  const PlanView v = planView(ev);
  const auto [sx, sy] = planAxes(svg, area, v);
  std::vector<std::pair<double, double>> gt_px;
  for (const auto& p : ev.gt_path) gt_px.emplace_back(sx(p[v.a]), sy(p[v.b]));
  svg.polyline(thin(gt_px, 0.7), "#555555", 1.6, "stroke-dasharray=\"5,3\"");

  // Under the estimate, where the estimator was weak.
  std::vector<std::pair<double, double>> est_px;
  for (const auto& T : ev.est) est_px.emplace_back(sx(T.translation()[v.a]), sy(T.translation()[v.b]));
  const bool degenerate_drawn =
      overlayRuns(svg, est_px, ev.est_stamps, inSpans(ev.est_stamps, marks.degenerate), max_step, kDegenerateColour);
  const bool predicted_drawn =
      overlayRuns(svg, est_px, ev.est_stamps, inSpans(ev.est_stamps, marks.predicted), max_step, kPredictedColour);
  errorColouredPath(svg, est_px, ev, err_lo, err_hi, max_step);
  const bool loops_drawn = loopLines(svg, est_px, ev.est_stamps, marks.loops);
  if (!ev.est.empty()) startAndEnd(svg, est_px.front(), est_px.back());
  topViewLegend(svg, area, degenerate_drawn, predicted_drawn, loops_drawn);
}

void colourBar(Svg& svg, const Rect& r, double err_lo, double err_hi) {
  svg.os << "<defs><linearGradient id=\"ate\" x1=\"0\" y1=\"1\" x2=\"0\" y2=\"0\">";
  for (int i = 0; i <= 8; ++i)
    svg.os << "<stop offset=\"" << i / 8.0 << "\" stop-color=\"" << errorColour(i / 8.0) << "\"/>";
  svg.os << "</linearGradient></defs>\n";
  svg.os << "<rect x=\"" << fixed1(r.x) << "\" y=\"" << fixed1(r.y) << "\" width=\"" << fixed1(r.w) << "\" height=\""
         << fixed1(r.h) << "\" fill=\"url(#ate)\" stroke=\"#444444\"/>\n";
  LinearScale s{err_lo, err_hi, r.y + r.h, r.y};
  const auto ticks = niceTicks(err_lo, err_hi, 6);
  const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 1.0;
  for (double v : ticks) {
    svg.line(r.x + r.w, s(v), r.x + r.w + 5, s(v), "#444444", 1);
    svg.text(r.x + r.w + 8, s(v) + 4.5, tickLabel(v, step), 13);
  }
  std::ostringstream rot;
  rot << "transform=\"rotate(-90 " << fixed1(r.x + r.w + 62) << " " << fixed1(r.y + r.h / 2) << ")\"";
  svg.text(r.x + r.w + 62, r.y + r.h / 2, "ATE (m)", 15, "middle", rot.str().c_str());
}

/// The marks on a panel's time axis: shaded degenerate and predicted stretches, a dashed line at
/// each loop closure.
void shadeTimeMarks(Svg& svg, const Rect& r, const LinearScale& sx, const TimeMarks& marks) {
  auto shade = [&](const std::vector<std::pair<double, double>>& spans, const char* colour) {
    for (const auto& [from, to] : spans) {
      if (to < sx.lo || from > sx.hi) continue;
      const double x0 = sx(std::max(from, sx.lo)), x1 = sx(std::min(to, sx.hi));
      svg.os << "<rect x=\"" << fixed1(x0) << "\" y=\"" << fixed1(r.y) << "\" width=\""
             << fixed1(std::max(1.5, x1 - x0)) << "\" height=\"" << fixed1(r.h) << "\" fill=\"" << colour
             << "\" fill-opacity=\"0.2\"/>\n";
    }
  };
  shade(marks.degenerate, kDegenerateColour);
  shade(marks.predicted, kPredictedColour);
  for (double t : marks.loops)
    if (t >= sx.lo && t <= sx.hi)
      svg.line(sx(t), r.y, sx(t), r.y + r.h, kLoopColour, 1.0, "stroke-dasharray=\"4,3\" stroke-opacity=\"0.7\"");
}

/// The key of a series panel: line samples with the RMSE and median, and the max (and how many
/// values were clipped), laid out right to left from the panel's corner.
void seriesKey(Svg& svg, const Rect& r, const ErrorStatistics& stats, size_t clipped) {
  const std::string rmse_label = "rmse " + number(stats.rmse), median_label = "median " + number(stats.median);
  std::string max_label = "max " + number(stats.max);
  if (clipped) max_label += " (" + std::to_string(clipped) + " above the axis)";
  auto width = [](const std::string& text) { return 7.4 * static_cast<double>(text.size()); };  // 13 px sans
  const double sample = 26, pad = 8, space = 16;
  const double kw =
      pad + sample + 6 + width(rmse_label) + space + sample + 6 + width(median_label) + space + width(max_label) + pad;
  const double kx = r.x + r.w - kw - 6, ky = r.y + 6;
  svg.os << "<rect x=\"" << fixed1(kx) << "\" y=\"" << fixed1(ky) << "\" width=\"" << fixed1(kw) << "\" height=\"22\" "
         << "fill=\"#ffffff\" fill-opacity=\"0.9\" stroke=\"#bbbbbb\"/>\n";
  double x = kx + pad;
  svg.line(x, ky + 11, x + sample, ky + 11, "#222222", 1.4, "stroke-dasharray=\"7,4\"");
  svg.text(x + sample + 6, ky + 16, rmse_label, 13);
  x += sample + 6 + width(rmse_label) + space;
  svg.line(x, ky + 11, x + sample, ky + 11, "#1a9641", 1.6, "stroke-dasharray=\"2,3\"");
  svg.text(x + sample + 6, ky + 16, median_label, 13);
  x += sample + 6 + width(median_label) + space;
  svg.text(x, ky + 16, max_label, 13);
}

/// One error series over time, with dashed RMSE and dotted median lines, over the marks; the line
/// breaks where consecutive samples are more than `max_step` apart. When a few spikes
/// dwarf the rest, the axis stops above the 99th percentile and the clipped values sit on the
/// top edge (the panel says how many).
void seriesPanel(Svg& svg, const Rect& r, const std::vector<double>& t, const std::vector<double>& e, double t0,
                 double t1, double max_step, const std::string& xtitle, const std::string& ytitle,
                 const std::string& colour, const ErrorStatistics& stats, const TimeMarks& marks) {
  double ylo = 0.0, yhi = e.empty() ? 1.0 : *std::max_element(e.begin(), e.end());
  if (e.size() >= 100) {
    std::vector<double> sorted = e;
    const size_t k = sorted.size() * 99 / 100;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(k), sorted.end());
    const double limit = std::max(1.5 * sorted[k], 1.2 * stats.rmse);
    if (yhi > 2.0 * limit) yhi = limit;
  }
  if (!(yhi > 0.0)) yhi = 1.0;
  niceRange(ylo, yhi, 5);
  ylo = 0.0;
  const auto [sx, sy] = axes(svg, r, t0, t1, ylo, yhi, xtitle, ytitle, 8, 5);
  shadeTimeMarks(svg, r, sx, marks);
  // Per pixel column keep the first, highest and lowest value, so spikes survive thinning.
  std::vector<std::pair<double, double>> pts;
  size_t clipped = 0;
  int column = -1;
  double col_min = 0, col_max = 0, col_first = 0, col_x = 0;
  auto flush = [&]() {
    if (column < 0) return;
    pts.emplace_back(col_x, sy(col_first));
    if (col_max != col_first) pts.emplace_back(col_x, sy(col_max));
    if (col_min != col_first && col_min != col_max) pts.emplace_back(col_x, sy(col_min));
  };
  for (size_t k = 0; k < t.size(); ++k) {
    if (k > 0 && std::abs(t[k] - t[k - 1]) > max_step) {  // a gap in the estimate: break the line
      flush();
      svg.polyline(pts, colour, 1.3);
      pts.clear();
      column = -1;
    }
    const double x = sx(t[k]);
    const int c = static_cast<int>(std::floor(x));
    double v = e[k];
    if (v > yhi) v = yhi, ++clipped;
    if (c != column) {
      flush();
      column = c, col_x = x, col_first = col_min = col_max = v;
    } else {
      col_min = std::min(col_min, v), col_max = std::max(col_max, v);
    }
  }
  flush();
  if (pts.size() == 1) pts.push_back(pts.front());
  svg.polyline(pts, colour, 1.3);
  if (stats.count == 0) {
    svg.text(r.x + r.w / 2, r.y + r.h / 2, "no pairs", 15, "middle");
    return;
  }
  svg.line(r.x, sy(stats.rmse), r.x + r.w, sy(stats.rmse), "#222222", 1.4, "stroke-dasharray=\"7,4\"");
  svg.line(r.x, sy(stats.median), r.x + r.w, sy(stats.median), "#1a9641", 1.6, "stroke-dasharray=\"2,3\"");
  seriesKey(svg, r, stats, clipped);
}

}  // namespace

std::string evaluationSvg(const Evaluation& ev, const PlotOptions& options) {
  Svg svg;
  const double W = options.width, H = options.height;
  svg.os << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H << "\" viewBox=\"0 0 " << W
         << " " << H << "\">\n"
         << "<rect width=\"100%\" height=\"100%\" fill=\"#fafafa\"/>\n";
  svg.text(24, 32, options.title, 19, "start", "font-weight=\"bold\"");
  std::ostringstream sub;
  sub << "ATE rmse " << number(ev.ate.rmse) << " m, mean " << number(ev.ate.mean) << " m, max " << number(ev.ate.max)
      << " m over " << ev.pairs.size() << " pairs; coverage " << number(100.0 * ev.coverage.fraction, 4) << " %";
  if (ev.drift.segments > 0)
    sub << "; KITTI drift " << number(ev.drift.translation_percent) << " %, " << number(ev.drift.rotation_deg_per_m)
        << " deg/m";
  svg.text(24, 56, sub.str(), 15);

  double err_lo = ev.ate.count ? ev.ate.min : 0.0, err_hi = ev.ate.count ? ev.ate.max : 1.0;
  if (!(err_hi > err_lo)) err_hi = err_lo + 1e-9;

  const double top = 80, bottom_margin = 62;
  const double view_size = std::min(H - top - bottom_margin, 0.5 * W - 150);
  const Rect view{84, top, view_size, view_size};
  // Lines break where the estimate has a gap longer than the coverage threshold.
  const double max_step = ev.coverage.gap > 0.0 ? ev.coverage.gap : INFINITY;
  // Marks need stamps: none on poses paired by index.
  const PlotMarks marks = ev.pairs.by_index ? PlotMarks{} : options.marks;
  topView(svg, view, ev, err_lo, err_hi, max_step, marks);
  colourBar(svg, Rect{view.x + view.w + 16, view.y, 20, view.h}, err_lo, err_hi);

  // Right column: ATE, RPE translation and RPE rotation over time.
  const bool frames = ev.pairs.by_index;
  const double t0 = ev.est_stamps.empty() ? 0.0 : ev.est_stamps.front();
  std::vector<double> t_ate;
  for (double s : ev.est_stamps) t_ate.push_back(s - t0);
  std::vector<double> t_rpe;
  for (size_t j : ev.rpe.to) t_rpe.push_back(ev.est_stamps[j] - t0);
  double tmin = 0.0, tmax = 1.0;
  if (!t_ate.empty()) {
    tmin = *std::min_element(t_ate.begin(), t_ate.end());
    tmax = *std::max_element(t_ate.begin(), t_ate.end());
  }
  if (!(tmax > tmin)) tmax = tmin + 1.0;
  const std::string xtitle = frames ? "pose index" : "time since the first pair (s)";
  const double rx = view.x + view.w + 200, rw = W - rx - 30;
  const double gap = 62, ph = (view.h - 2 * gap) / 3.0;
  // RPE samples are one pair stride apart.
  const double rpe_step =
      ev.rpe.from.size() > 1 ? max_step * static_cast<double>(ev.rpe.from[1] - ev.rpe.from[0]) : max_step;
  const TimeMarks time_marks = marksSinceStart(marks, t0);
  seriesPanel(svg, Rect{rx, top, rw, ph}, t_ate, ev.ate_m, tmin, tmax, max_step, xtitle, "ATE (m)", "#d7191c", ev.ate,
              time_marks);
  seriesPanel(svg, Rect{rx, top + ph + gap, rw, ph}, t_rpe, ev.rpe.translation_m, tmin, tmax, rpe_step, xtitle,
              "RPE (m)", "#2c7bb6", ev.rpe_translation_m, time_marks);
  seriesPanel(svg, Rect{rx, top + 2 * (ph + gap), rw, ph}, t_rpe, ev.rpe.rotation_deg, tmin, tmax, rpe_step, xtitle,
              "RPE (deg)", "#7b3294", ev.rpe_rotation_deg, time_marks);
  svg.os << "</svg>\n";
  return svg.os.str();
}

void writeEvaluationSvg(const std::string& path, const Evaluation& ev, const PlotOptions& options) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write");
  out << evaluationSvg(ev, options);
  if (!out) throw std::runtime_error(path + ": write failed");
}

}  // namespace livo::evaluate
