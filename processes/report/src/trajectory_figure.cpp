#include "livo/report/trajectory_figure.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "livo/plot_scale.hpp"
#include "livo/report/map_views.hpp"
#include "livo/text_format.hpp"

namespace livo::report {

namespace {

constexpr double kSpanSlack_s = 1e-3;  // a pose within this of a span's end is in it (TUM rounding)
const char* const kFont = "font-family=\"DejaVu Sans, Arial, sans-serif\"";

std::string fixed1(double v) { return formatFixed(v, 1); }
const char* const kEstimateColour = "#1f77b4";
const char* const kOdometryColour = "#9e9e9e";

struct Canvas {
  double x0 = 0, y0 = 0, s = 1;  // pixel = (x0 + s (x - xmin), y0 + s (ymax - y))
  double xmin = 0, ymax = 0;
  std::pair<double, double> operator()(const Vec3& p) const {
    return {x0 + s * (p.x() - xmin), y0 + s * (ymax - p.y())};
  }
};

void polyline(std::ostringstream& os, const std::vector<std::pair<double, double>>& pts, const std::string& stroke,
              double width, const std::string& extra = "") {
  if (pts.empty()) return;
  if (pts.size() == 1) {  // one pose: a dot as wide as the stroke
    std::string fill_extra = extra;
    if (const size_t at = fill_extra.find("stroke-opacity"); at != std::string::npos) fill_extra.replace(at, 6, "fill");
    os << "<circle cx=\"" << fixed1(pts[0].first) << "\" cy=\"" << fixed1(pts[0].second) << "\" r=\""
       << fixed1(0.5 * width) << "\" fill=\"" << stroke << "\" " << fill_extra << "/>\n";
    return;
  }
  os << "<polyline fill=\"none\" stroke=\"" << stroke << "\" stroke-width=\"" << width
     << "\" stroke-linejoin=\"round\" stroke-linecap=\"round\" " << extra << " points=\"";
  std::pair<double, double> last{NAN, NAN};
  for (size_t i = 0; i < pts.size(); ++i) {
    // drop points less than 0.5 px from the last one drawn (the last one is kept)
    if (i > 0 && i + 1 < pts.size() && std::hypot(pts[i].first - last.first, pts[i].second - last.second) < 0.5)
      continue;
    os << fixed1(pts[i].first) << "," << fixed1(pts[i].second) << " ";
    last = pts[i];
  }
  os << "\"/>\n";
}

bool sameTrajectory(const Trajectory& a, const Trajectory& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].stamp != b[i].stamp || !(a[i].pose.translation() - b[i].pose.translation()).isZero(1e-6)) return false;
  return true;
}

// The runs of consecutive poses of each piece whose stamps lie in one of the spans.
std::vector<std::vector<size_t>> runsInSpans(const Trajectory& t, const std::vector<std::pair<size_t, size_t>>& pieces,
                                             const std::vector<std::pair<double, double>>& spans) {
  std::vector<std::vector<size_t>> runs;
  for (const auto& [a, b] : spans)
    for (const auto& [begin, end] : pieces) {
      std::vector<size_t> run;
      for (size_t i = begin; i < end; ++i)
        if (t[i].stamp >= a - kSpanSlack_s && t[i].stamp <= b + kSpanSlack_s) run.push_back(i);
      if (!run.empty()) runs.push_back(run);
    }
  return runs;
}

// The index of the pose nearest in time to `stamp` (within `slack`), or -1.
long nearestPose(const Trajectory& t, double stamp, double slack) {
  if (!std::isfinite(stamp) || t.empty()) return -1;
  const auto it =
      std::lower_bound(t.begin(), t.end(), stamp, [](const StampedPose& p, double s) { return p.stamp < s; });
  long best = -1;
  double gap = slack;
  for (auto c : {it, it == t.begin() ? it : std::prev(it)}) {
    if (c == t.end()) continue;
    const double d = std::abs(c->stamp - stamp);
    if (d <= gap) gap = d, best = static_cast<long>(c - t.begin());
  }
  return best;
}

// The layout: title and legend above the plot, axis labels left and below.
constexpr double kLeft = 70, kRight = 24, kTop = 78, kBottom = 52;

// The figure's size and where the plot sits in it.
struct Layout {
  Canvas c;
  double width = 0, height = 0, plot_w = 0, plot_h = 0;
};

// The finite positions of the estimate and, when drawn, the odometry beneath it.
std::vector<Vec3> finitePositions(const Trajectory& est, const Trajectory* odometry) {
  std::vector<Vec3> all;
  for (const Trajectory* t : {&est, odometry})
    if (t)
      for (const StampedPose& p : *t)
        if (p.pose.translation().allFinite()) all.push_back(p.pose.translation());
  return all;
}

// `width` px wide, equal scales on both axes, the box in the middle with 3 % margins.
Layout figureLayout(const Box3& box, double width) {
  Layout l;
  l.width = width;
  l.plot_w = width - kLeft - kRight;
  const double dx = std::max(box.size().x(), 1.0), dy = std::max(box.size().y(), 1.0);
  l.plot_h = std::clamp(l.plot_w * dy / dx, 0.35 * l.plot_w, 1.1 * l.plot_w);
  const double s = std::min(l.plot_w / (dx * 1.06), l.plot_h / (dy * 1.06));  // px per m, 3 % margins
  l.c.s = s, l.c.x0 = kLeft, l.c.y0 = kTop;
  l.c.xmin = box.centre().x() - 0.5 * l.plot_w / s;
  l.c.ymax = box.centre().y() + 0.5 * l.plot_h / s;
  l.height = kTop + l.plot_h + kBottom;
  return l;
}

// The svg element, the background and the title.
void writeHeader(std::ostringstream& os, const Layout& l, const std::string& title) {
  os << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << fixed1(l.width) << "\" height=\"" << fixed1(l.height)
     << "\" viewBox=\"0 0 " << fixed1(l.width) << " " << fixed1(l.height) << "\">\n";
  os << "<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n";
  os << "<text x=\"" << fixed1(kLeft) << "\" y=\"24\" font-size=\"16\" " << kFont << ">" << escapeMarkup(title)
     << "</text>\n";
}

// Axes: ticks and a light grid, equal scales.
void writeAxes(std::ostringstream& os, const Layout& l) {
  const Canvas& c = l.c;
  const double plot_w = l.plot_w, plot_h = l.plot_h, s = c.s;
  const double x_lo = c.xmin, x_hi = c.xmin + plot_w / s, y_lo = c.ymax - plot_h / s, y_hi = c.ymax;
  const auto xt = niceTicks(x_lo, x_hi, 8), yt = niceTicks(y_lo, y_hi, 6);
  const double xstep = xt.size() > 1 ? xt[1] - xt[0] : 1.0, ystep = yt.size() > 1 ? yt[1] - yt[0] : 1.0;
  os << "<rect x=\"" << fixed1(kLeft) << "\" y=\"" << fixed1(kTop) << "\" width=\"" << fixed1(plot_w) << "\" height=\""
     << fixed1(plot_h) << "\" fill=\"none\" stroke=\"#888888\"/>\n";
  for (double x : xt) {
    const double px = c(Vec3(x, 0, 0)).first;
    os << "<line x1=\"" << fixed1(px) << "\" y1=\"" << fixed1(kTop) << "\" x2=\"" << fixed1(px) << "\" y2=\""
       << fixed1(kTop + plot_h) << "\" stroke=\"#e6e6e6\"/>\n";
    os << "<text x=\"" << fixed1(px) << "\" y=\"" << fixed1(kTop + plot_h + 18)
       << "\" font-size=\"12\" text-anchor=\"middle\" " << kFont << ">" << tickLabel(x, xstep) << "</text>\n";
  }
  for (double y : yt) {
    const double py = c(Vec3(0, y, 0)).second;
    os << "<line x1=\"" << fixed1(kLeft) << "\" y1=\"" << fixed1(py) << "\" x2=\"" << fixed1(kLeft + plot_w)
       << "\" y2=\"" << fixed1(py) << "\" stroke=\"#e6e6e6\"/>\n";
    os << "<text x=\"" << fixed1(kLeft - 8) << "\" y=\"" << fixed1(py + 4) << "\" font-size=\"12\" text-anchor=\"end\" "
       << kFont << ">" << tickLabel(y, ystep) << "</text>\n";
  }
  os << "<text x=\"" << fixed1(kLeft + 0.5 * plot_w) << "\" y=\"" << fixed1(l.height - 12) << "\" font-size=\"13\" "
     << "text-anchor=\"middle\" " << kFont << ">x (m)</text>\n";
  os << "<text x=\"18\" y=\"" << fixed1(kTop + 0.5 * plot_h) << "\" font-size=\"13\" text-anchor=\"middle\" "
     << "transform=\"rotate(-90 18 " << fixed1(kTop + 0.5 * plot_h) << ")\" " << kFont << ">y (m)</text>\n";
}

// The pixels of the poses `idx` of `t`.
std::vector<std::pair<double, double>> pixels(const Canvas& c, const Trajectory& t, const std::vector<size_t>& idx) {
  std::vector<std::pair<double, double>> px;
  for (size_t i : idx) px.push_back(c(t[i].pose.translation()));
  return px;
}

std::vector<size_t> indexRange(size_t a, size_t b) {
  std::vector<size_t> v;
  for (size_t i = a; i < b; ++i) v.push_back(i);
  return v;
}

// Each piece of `t` as one line.
void drawPieces(std::ostringstream& os, const Canvas& c, const Trajectory& t,
                const std::vector<std::pair<size_t, size_t>>& pieces, const char* colour, double width) {
  for (const auto& [a, b] : pieces) polyline(os, pixels(c, t, indexRange(a, b)), colour, width);
}

// Each run as a wide translucent stroke beneath the path.
void drawRuns(std::ostringstream& os, const Canvas& c, const Trajectory& t,
              const std::vector<std::vector<size_t>>& runs, const char* colour) {
  for (const auto& run : runs) polyline(os, pixels(c, t, run), colour, 9, "stroke-opacity=\"0.45\"");
}

// Each loop closure as a dashed line between the poses nearest its keyframes' stamps, a dot at
// each end; returns how many could be placed.
size_t drawLoops(std::ostringstream& os, const Canvas& c, const Trajectory& est,
                 const std::vector<PlotMarks::Loop>& loops) {
  size_t drawn = 0;
  for (const auto& l : loops) {
    const long a = nearestPose(est, l.from_stamp, 0.25), b = nearestPose(est, l.to_stamp, 0.25);
    if (a < 0 || b < 0) continue;
    const auto pa = c(est[a].pose.translation()), pb = c(est[b].pose.translation());
    os << "<line x1=\"" << fixed1(pa.first) << "\" y1=\"" << fixed1(pa.second) << "\" x2=\"" << fixed1(pb.first)
       << "\" y2=\"" << fixed1(pb.second) << "\" stroke=\"" << kLoopColour
       << "\" stroke-width=\"1.8\" stroke-dasharray=\"6,3\"/>\n";
    for (const auto& p : {pa, pb})
      os << "<circle cx=\"" << fixed1(p.first) << "\" cy=\"" << fixed1(p.second) << "\" r=\"3.5\" fill=\""
         << kLoopColour << "\"/>\n";
    ++drawn;
  }
  return drawn;
}

// A green dot at the start, a red square at the end.
void drawStartEnd(std::ostringstream& os, std::pair<double, double> start, std::pair<double, double> end) {
  os << "<circle cx=\"" << fixed1(start.first) << "\" cy=\"" << fixed1(start.second) << "\" r=\"5\" fill=\"#3cb43c\" "
     << "stroke=\"#282828\"/>\n";
  os << "<rect x=\"" << fixed1(end.first - 4.5) << "\" y=\"" << fixed1(end.second - 4.5)
     << "\" width=\"9\" height=\"9\" "
     << "fill=\"#dc2828\" stroke=\"#282828\"/>\n";
}

struct LegendItem {
  std::string swatch, label;
};

// What the figure drew, for its legend.
struct DrawnMarks {
  bool odometry = false, degenerate = false, predicted = false, loops = false;
};

std::string legendStroke(const char* colour, double w, const char* extra) {
  return std::string("<line x1=\"0\" y1=\"0\" x2=\"26\" y2=\"0\" stroke=\"") + colour + "\" stroke-width=\"" +
         fixed1(w) + "\" " + extra + "/>";
}

// The legend's entries: only what is drawn.
std::vector<LegendItem> legendItems(const std::string& estimate_label, const DrawnMarks& drawn) {
  std::vector<LegendItem> items;
  items.push_back({legendStroke(kEstimateColour, 1.8, ""), estimate_label});
  if (drawn.odometry) items.push_back({legendStroke(kOdometryColour, 1.2, ""), "online odometry"});
  if (drawn.degenerate)
    items.push_back({legendStroke(kDegenerateColour, 9, "stroke-opacity=\"0.45\""), "degenerate sweeps"});
  if (drawn.predicted)
    items.push_back({legendStroke(kPredictedColour, 9, "stroke-opacity=\"0.45\""), "predicted, no LiDAR update"});
  if (drawn.loops)
    items.push_back({legendStroke(kLoopColour, 1.8, "stroke-dasharray=\"6,3\"") +
                         "<circle cx=\"0\" cy=\"0\" r=\"3.5\" fill=\"" + kLoopColour +
                         "\"/><circle cx=\"26\" cy=\"0\" "
                         "r=\"3.5\" fill=\"" +
                         kLoopColour + "\"/>",
                     "loop closure"});
  items.push_back(
      {"<circle cx=\"8\" cy=\"0\" r=\"5\" fill=\"#3cb43c\" stroke=\"#282828\"/><rect x=\"17\" y=\"-4.5\" "
       "width=\"9\" height=\"9\" fill=\"#dc2828\" stroke=\"#282828\"/>",
       "start, end"});
  return items;
}

// The legend: one row above the plot.
void writeLegend(std::ostringstream& os, const std::vector<LegendItem>& items) {
  double x = kLeft;
  for (const LegendItem& item : items) {
    os << "<g transform=\"translate(" << fixed1(x) << " 52)\">" << item.swatch
       << "<text x=\"34\" y=\"4\" font-size=\"12\" " << kFont << ">" << escapeMarkup(item.label) << "</text></g>\n";
    x += 46 + 7.0 * static_cast<double>(item.label.size());
  }
}

}  // namespace

std::string trajectoryTopSvg(const TrajectoryFigureInputs& in, double width) {
  const bool has_final = !in.final_estimate.empty();
  const Trajectory& est = has_final ? in.final_estimate : in.odometry;
  const bool draw_odometry = has_final && !in.odometry.empty() && !sameTrajectory(in.final_estimate, in.odometry);
  const std::vector<Vec3> all = finitePositions(est, draw_odometry ? &in.odometry : nullptr);
  if (all.empty()) throw std::invalid_argument("trajectoryTopSvg: no finite pose");
  const Layout layout = figureLayout(percentileBox(all, 0.0, 1.0), width);
  const Canvas& c = layout.c;
  const auto pieces = pathPieces(est, in.reset_stamps);
  if (pieces.empty()) throw std::invalid_argument("trajectoryTopSvg: no finite pose in the estimate");
  const auto degenerate = runsInSpans(est, pieces, in.marks.degenerate);
  const auto predicted = runsInSpans(est, pieces, in.marks.predicted);

  std::ostringstream os;
  writeHeader(os, layout, in.title);
  writeAxes(os, layout);
  drawRuns(os, c, est, predicted, kPredictedColour);
  drawRuns(os, c, est, degenerate, kDegenerateColour);
  if (draw_odometry) drawPieces(os, c, in.odometry, pathPieces(in.odometry, in.reset_stamps), kOdometryColour, 1.2);
  drawPieces(os, c, est, pieces, kEstimateColour, 1.8);
  const size_t loops_drawn = drawLoops(os, c, est, in.marks.loops);
  drawStartEnd(os, c(est[pieces.front().first].pose.translation()),
               c(est[pieces.back().second - 1].pose.translation()));
  const DrawnMarks drawn{draw_odometry, !degenerate.empty(), !predicted.empty(), loops_drawn > 0};
  writeLegend(os, legendItems(has_final ? "trajectory (trajectory.tum)" : "odometry (odometry.tum)", drawn));
  os << "</svg>\n";
  return os.str();
}

}  // namespace livo::report
