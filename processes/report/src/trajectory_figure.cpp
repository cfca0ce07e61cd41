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

}  // namespace

std::string trajectoryTopSvg(const TrajectoryFigureInputs& in, double width) {
  const bool has_final = !in.final_estimate.empty();
  const Trajectory& est = has_final ? in.final_estimate : in.odometry;
  const bool draw_odometry = has_final && !in.odometry.empty() && !sameTrajectory(in.final_estimate, in.odometry);
  std::vector<Vec3> all;
  for (const Trajectory* t : {&est, draw_odometry ? &in.odometry : nullptr})
    if (t)
      for (const StampedPose& p : *t)
        if (p.pose.translation().allFinite()) all.push_back(p.pose.translation());
  if (all.empty()) throw std::invalid_argument("trajectoryTopSvg: no finite pose");
  const Box3 box = percentileBox(all, 0.0, 1.0);

  // layout: title and legend above the plot, axis labels left and below
  constexpr double kLeft = 70, kRight = 24, kTop = 78, kBottom = 52;
  const double plot_w = width - kLeft - kRight;
  const double dx = std::max(box.size().x(), 1.0), dy = std::max(box.size().y(), 1.0);
  const double plot_h = std::clamp(plot_w * dy / dx, 0.35 * plot_w, 1.1 * plot_w);
  const double s = std::min(plot_w / (dx * 1.06), plot_h / (dy * 1.06));  // px per m, 3 % margins
  Canvas c;
  c.s = s, c.x0 = kLeft, c.y0 = kTop;
  c.xmin = box.centre().x() - 0.5 * plot_w / s;
  c.ymax = box.centre().y() + 0.5 * plot_h / s;
  const double height = kTop + plot_h + kBottom;

  std::ostringstream os;
  os << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << fixed1(width) << "\" height=\"" << fixed1(height)
     << "\" viewBox=\"0 0 " << fixed1(width) << " " << fixed1(height) << "\">\n";
  os << "<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n";
  os << "<text x=\"" << fixed1(kLeft) << "\" y=\"24\" font-size=\"16\" " << kFont << ">" << escapeMarkup(in.title)
     << "</text>\n";

  // axes: ticks and a light grid, equal scales
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
  os << "<text x=\"" << fixed1(kLeft + 0.5 * plot_w) << "\" y=\"" << fixed1(height - 12) << "\" font-size=\"13\" "
     << "text-anchor=\"middle\" " << kFont << ">x (m)</text>\n";
  os << "<text x=\"18\" y=\"" << fixed1(kTop + 0.5 * plot_h) << "\" font-size=\"13\" text-anchor=\"middle\" "
     << "transform=\"rotate(-90 18 " << fixed1(kTop + 0.5 * plot_h) << ")\" " << kFont << ">y (m)</text>\n";

  auto pixels = [&](const Trajectory& t, const std::vector<size_t>& idx) {
    std::vector<std::pair<double, double>> px;
    for (size_t i : idx) px.push_back(c(t[i].pose.translation()));
    return px;
  };
  auto range = [](size_t a, size_t b) {
    std::vector<size_t> v;
    for (size_t i = a; i < b; ++i) v.push_back(i);
    return v;
  };
  const auto pieces = pathPieces(est, in.reset_stamps);
  if (pieces.empty()) throw std::invalid_argument("trajectoryTopSvg: no finite pose in the estimate");
  const auto degenerate = runsInSpans(est, pieces, in.marks.degenerate);
  const auto predicted = runsInSpans(est, pieces, in.marks.predicted);
  for (const auto& run : predicted) polyline(os, pixels(est, run), kPredictedColour, 9, "stroke-opacity=\"0.45\"");
  for (const auto& run : degenerate) polyline(os, pixels(est, run), kDegenerateColour, 9, "stroke-opacity=\"0.45\"");
  if (draw_odometry)
    for (const auto& [a, b] : pathPieces(in.odometry, in.reset_stamps))
      polyline(os, pixels(in.odometry, range(a, b)), kOdometryColour, 1.2);
  for (const auto& [a, b] : pieces) polyline(os, pixels(est, range(a, b)), kEstimateColour, 1.8);
  size_t loops_drawn = 0;
  for (const auto& l : in.marks.loops) {
    const long a = nearestPose(est, l.from_stamp, 0.25), b = nearestPose(est, l.to_stamp, 0.25);
    if (a < 0 || b < 0) continue;
    const auto pa = c(est[a].pose.translation()), pb = c(est[b].pose.translation());
    os << "<line x1=\"" << fixed1(pa.first) << "\" y1=\"" << fixed1(pa.second) << "\" x2=\"" << fixed1(pb.first)
       << "\" y2=\"" << fixed1(pb.second) << "\" stroke=\"" << kLoopColour
       << "\" stroke-width=\"1.8\" stroke-dasharray=\"6,3\"/>\n";
    for (const auto& p : {pa, pb})
      os << "<circle cx=\"" << fixed1(p.first) << "\" cy=\"" << fixed1(p.second) << "\" r=\"3.5\" fill=\""
         << kLoopColour << "\"/>\n";
    ++loops_drawn;
  }
  const auto start = c(est[pieces.front().first].pose.translation());
  const auto end = c(est[pieces.back().second - 1].pose.translation());
  os << "<circle cx=\"" << fixed1(start.first) << "\" cy=\"" << fixed1(start.second) << "\" r=\"5\" fill=\"#3cb43c\" "
     << "stroke=\"#282828\"/>\n";
  os << "<rect x=\"" << fixed1(end.first - 4.5) << "\" y=\"" << fixed1(end.second - 4.5)
     << "\" width=\"9\" height=\"9\" "
     << "fill=\"#dc2828\" stroke=\"#282828\"/>\n";

  // legend: one row above the plot, only what is drawn
  struct Item {
    std::string swatch, label;
  };
  std::vector<Item> items;
  auto stroke = [](const char* colour, double w, const char* extra) {
    return std::string("<line x1=\"0\" y1=\"0\" x2=\"26\" y2=\"0\" stroke=\"") + colour + "\" stroke-width=\"" +
           fixed1(w) + "\" " + extra + "/>";
  };
  items.push_back(
      {stroke(kEstimateColour, 1.8, ""), has_final ? "trajectory (trajectory.tum)" : "odometry (odometry.tum)"});
  if (draw_odometry) items.push_back({stroke(kOdometryColour, 1.2, ""), "online odometry"});
  if (!degenerate.empty())
    items.push_back({stroke(kDegenerateColour, 9, "stroke-opacity=\"0.45\""), "degenerate sweeps"});
  if (!predicted.empty())
    items.push_back({stroke(kPredictedColour, 9, "stroke-opacity=\"0.45\""), "predicted, no LiDAR update"});
  if (loops_drawn > 0)
    items.push_back({stroke(kLoopColour, 1.8, "stroke-dasharray=\"6,3\"") +
                         "<circle cx=\"0\" cy=\"0\" r=\"3.5\" fill=\"" + kLoopColour +
                         "\"/><circle cx=\"26\" cy=\"0\" "
                         "r=\"3.5\" fill=\"" +
                         kLoopColour + "\"/>",
                     "loop closure"});
  items.push_back(
      {"<circle cx=\"8\" cy=\"0\" r=\"5\" fill=\"#3cb43c\" stroke=\"#282828\"/><rect x=\"17\" y=\"-4.5\" "
       "width=\"9\" height=\"9\" fill=\"#dc2828\" stroke=\"#282828\"/>",
       "start, end"});
  double x = kLeft;
  for (const Item& item : items) {
    os << "<g transform=\"translate(" << fixed1(x) << " 52)\">" << item.swatch
       << "<text x=\"34\" y=\"4\" font-size=\"12\" " << kFont << ">" << escapeMarkup(item.label) << "</text></g>\n";
    x += 46 + 7.0 * static_cast<double>(item.label.size());
  }
  os << "</svg>\n";
  return os.str();
}

}  // namespace livo::report
