#include "livo/report/weak_spots.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "livo/reason_counts.hpp"
#include "livo/text_format.hpp"

namespace livo::report {

namespace {

const double kCos30 = std::cos(M_PI / 6.0);

/// The most frequent of `words` (the first seen on a tie) and its share; empty for no words.
std::pair<std::string, double> mostFrequent(const std::vector<std::string>& words) {
  std::map<std::string, size_t> counts;
  for (const std::string& w : words) ++counts[w];
  std::pair<std::string, size_t> best{"", 0};
  for (const std::string& w : words)
    if (counts[w] > best.second) best = {w, counts[w]};
  return {best.first, words.empty() ? 0.0 : static_cast<double>(best.second) / static_cast<double>(words.size())};
}

constexpr double kSameDuration_s = 1e-3;  // stamps' rounding: durations this close are equal

/// Longer (duration, then samples) first; stable sorts keep the earlier first on a tie.
bool longer(const TimeSpan& a, const TimeSpan& b) {
  if (std::abs(a.duration() - b.duration()) > kSameDuration_s) return a.duration() > b.duration();
  return a.count > b.count;
}

std::vector<std::string> degenerateDescriptions(const PipelineOutputs& o, std::vector<bool>* degenerate) {
  std::vector<std::string> words(o.odometry.size());
  degenerate->assign(o.odometry.size(), false);
  for (size_t i = 0; i < o.odometry.size(); ++i) {
    const OdometryQuality& q = o.odometry_quality[i];
    (*degenerate)[i] = q.degenerate;
    if (q.degenerate) words[i] = describe(weakAxis(q.position_covariance, q.velocity, o.odometry[i].pose.linear()));
  }
  return words;
}

/// Sweeps without a LiDAR update: no residual, except the first of each epoch (it seeds the map).
std::vector<bool> predictedSweeps(const PipelineOutputs& o) {
  std::vector<bool> predicted(o.odometry.size(), false);
  int32_t epoch = -1;
  for (size_t i = 0; i < o.odometry.size(); ++i) {
    const bool first_of_epoch = o.odometry_frames[i].epoch != epoch;
    epoch = o.odometry_frames[i].epoch;
    predicted[i] = !first_of_epoch && o.odometry_quality[i].num_residuals == 0;
  }
  return predicted;
}

std::vector<double> stampsOf(const Trajectory& t) {
  std::vector<double> s;
  s.reserve(t.size());
  for (const StampedPose& p : t) s.push_back(p.stamp);
  return s;
}

int64_t countOf(const std::vector<bool>& flags) { return std::count(flags.begin(), flags.end(), true); }

std::vector<VisualRefusals> visualRefusals(const PipelineOutputs& o, const std::string& camera_channel) {
  std::map<std::string, VisualRefusals> by_node;
  std::map<std::string, std::pair<std::vector<double>, std::vector<bool>>> kept;  // node -> stamps, kept
  for (const VisualAnswer& a : o.visual_answers) {
    VisualRefusals& v = by_node[a.source];
    v.node = a.source;
    v.what = "priors kept";
    ++v.of;
    v.refused += a.valid ? 0 : 1;
    kept[a.source].first.push_back(a.stamp);
    kept[a.source].second.push_back(!a.valid);
  }
  for (auto& [node, k] : kept) by_node[node].spans = mergeFlaggedRuns(k.first, k.second);
  for (const auto& [node, h] : o.final_health) {
    const auto parsed = parseReasonCounts(h.message);
    if (!parsed) continue;
    const bool answered = kept.count(node) > 0;  // it answered priors: those are counted above
    VisualRefusals& v = by_node[node];
    v.node = node;
    v.what = parsed->what;
    v.reasons = parsed->reasons.counts();
    if (answered) continue;
    v.refused = parsed->reasons.total();
    for (const channel_stats_t& c : h.channels)
      if (c.channel == camera_channel) v.of = c.messages;
  }
  std::vector<VisualRefusals> out;
  for (auto& [node, v] : by_node) out.push_back(std::move(v));
  return out;
}

std::vector<LoopMark> loopMarks(const PipelineOutputs& o) {
  std::map<int64_t, double> keyframe_stamps;
  for (const KeyframePose& k : o.keyframes) keyframe_stamps[k.id] = k.stamp;
  auto stampOf = [&](int64_t id) {
    auto it = keyframe_stamps.find(id);
    return it == keyframe_stamps.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
  };
  std::vector<LoopMark> out;
  for (const LoopEvent& e : o.loops) out.push_back({e, stampOf(e.from_id), stampOf(e.to_id)});
  return out;
}

// ---- JSON ----------------------------------------------------------------------------------------

nlohmann::json spanJson(const TimeSpan& s) { return {{"from", s.from}, {"to", s.to}, {"count", s.count}}; }
TimeSpan spanFrom(const nlohmann::json& j) {
  return {j.at("from").get<double>(), j.at("to").get<double>(), j.at("count").get<int64_t>()};
}
nlohmann::json spansJson(const std::vector<TimeSpan>& spans) {
  nlohmann::json a = nlohmann::json::array();
  for (const TimeSpan& s : spans) a.push_back(spanJson(s));
  return a;
}
std::vector<TimeSpan> spansFrom(const nlohmann::json& j) {
  std::vector<TimeSpan> out;
  for (const auto& s : j) out.push_back(spanFrom(s));
  return out;
}
// NaN is written as null (JSON has no NaN) and read back so.
double numberOrNan(const nlohmann::json& j) {
  return j.is_number() ? j.get<double>() : std::numeric_limits<double>::quiet_NaN();
}

// ---- Markdown ------------------------------------------------------------------------------------

/// "1 sweep", "2 sweeps".
std::string counted(int64_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

std::string seconds(double stamp, double start) { return formatFixed(stamp - start, 1); }

std::string percent(int64_t n, int64_t of) {
  return of > 0 ? formatFixed(100.0 * static_cast<double>(n) / static_cast<double>(of), 1) + " %" : "?";
}

/// "and 5 shorter stretches (7 sweeps, at most 2 each)": the spans from `first` on (longest first).
std::string shorterStretches(const std::vector<TimeSpan>& longest, size_t first, const char* one, const char* many) {
  int64_t samples = 0, most = 0;
  for (size_t i = first; i < longest.size(); ++i) {
    samples += longest[i].count;
    most = std::max(most, longest[i].count);
  }
  return "and " + counted(static_cast<int64_t>(longest.size() - first), "shorter stretch", "shorter stretches") + " (" +
         counted(samples, one, many) + ", at most " + std::to_string(most) + " each)";
}

/// "3.1–5.2 s (20), 7.0 s (1)": the longest spans, then how many more.
std::string spanList(const std::vector<TimeSpan>& spans, double start, const char* one, const char* many) {
  const std::vector<TimeSpan> longest = longestFirst(spans);
  std::ostringstream s;
  for (size_t i = 0; i < longest.size() && i < kListedStretches; ++i) {
    const TimeSpan& t = longest[i];
    s << (i ? ", " : "") << seconds(t.from, start);
    if (t.count > 1) s << "–" << seconds(t.to, start);
    s << " s (" << t.count << ")";
  }
  if (longest.size() > kListedStretches) s << " " << shorterStretches(longest, kListedStretches, one, many);
  return s.str();
}

void degenerateMarkdown(const WeakSpots& w, std::ostream& md) {
  md << "**Degenerate sweeps** (`ODOMETRY.degenerate`: the LiDAR left some direction to the prediction): ";
  if (w.degenerate == 0) {
    md << "none of " << w.sweeps << ".\n\n";
    return;
  }
  md << w.degenerate << " of " << w.sweeps << " (" << percent(w.degenerate, w.sweeps) << ") in "
     << counted(static_cast<int64_t>(w.degenerate_stretches.size()), "stretch", "stretches")
     << ". Least certain (the largest eigenvalue of the position covariance): " << w.direction << " on "
     << formatFixed(100.0 * w.direction_share, 0) << " % of them.\n\n";
  std::vector<DegenerateStretch> order = w.degenerate_stretches;
  std::stable_sort(order.begin(), order.end(),
                   [](const DegenerateStretch& a, const DegenerateStretch& b) { return longer(a.span, b.span); });
  md << "| from s | to s | sweeps | least certain |\n| --- | --- | --- | --- |\n";
  std::vector<TimeSpan> spans;
  for (const DegenerateStretch& d : order) {
    if (spans.size() < kListedStretches)
      md << "| " << seconds(d.span.from, w.start) << " | " << seconds(d.span.to, w.start) << " | " << d.span.count
         << " | " << d.direction << " |\n";
    spans.push_back(d.span);
  }
  md << "\n";
  if (spans.size() > kListedStretches) md << shorterStretches(spans, kListedStretches, "sweep", "sweeps") << ".\n\n";
}

void predictedMarkdown(const WeakSpots& w, std::ostream& md) {
  md << "**Predicted without a LiDAR update** (`ODOMETRY.num_residuals` 0 after an epoch's first sweep): ";
  if (w.predicted == 0) {
    md << "none.\n\n";
    return;
  }
  md << w.predicted << " of " << w.sweeps << " sweeps (" << percent(w.predicted, w.sweeps)
     << "): " << spanList(w.predicted_spans, w.start, "sweep", "sweeps") << ".\n\n";
}

std::string reasonList(const std::map<std::string, int64_t>& reasons) {
  std::vector<std::pair<std::string, int64_t>> order(reasons.begin(), reasons.end());
  std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  std::ostringstream s;
  for (size_t i = 0; i < order.size(); ++i) s << (i ? ", " : "") << order[i].second << " × " << order[i].first;
  return s.str();
}

void visualMarkdown(const WeakSpots& w, std::ostream& md) {
  md << "**Images the VIO did not use**:";
  if (w.visual.empty()) {
    if (w.state_priors > 0)
      md << " no VIO answered the " << w.state_priors << " images lio handed over (it went on LiDAR-only).\n\n";
    else
      md << " no VIO ran.\n\n";
    return;
  }
  md << "\n\n";
  for (const VisualRefusals& v : w.visual) {
    md << "- " << v.node << ": ";
    if (v.refused == 0) {
      md << "none" << (v.of > 0 ? " of " + std::to_string(v.of) : std::string()) << ".\n";
      continue;
    }
    md << v.refused;
    if (v.of > 0) md << " of " << v.of;
    md << " images (" << (v.of > 0 ? percent(v.refused, v.of) + "; " : std::string()) << v.what << "): ";
    md << (v.reasons.empty() ? std::string("the reasons are not in its HEALTH (see logs/") + v.node + ".log)"
                             : reasonList(v.reasons));
    if (!v.spans.empty()) md << "; when: " << spanList(v.spans, w.start, "image", "images");
    md << ".\n";
  }
  md << "\n";
}

void loopMarkdown(const WeakSpots& w, std::ostream& md) {
  md << "**Loop closures**: ";
  if (w.loops.empty()) {
    md << "none.\n\n";
    return;
  }
  std::vector<LoopMark> largest = w.loops;
  std::stable_sort(largest.begin(), largest.end(),
                   [](const LoopMark& a, const LoopMark& b) { return a.event.shift_m > b.event.shift_m; });
  md << w.loops.size();
  if (w.loops.size() == 1) {
    md << ", at " << seconds(w.loops.front().event.stamp, w.start) << " s.\n\n";
  } else {
    std::vector<double> shifts;
    double turn = 0.0;
    for (const LoopMark& l : w.loops) {
      shifts.push_back(l.event.shift_m);
      turn = std::max(turn, l.event.turn_deg);
    }
    std::nth_element(shifts.begin(), shifts.begin() + static_cast<std::ptrdiff_t>(shifts.size() / 2), shifts.end());
    md << ", from " << seconds(w.loops.front().event.stamp, w.start) << " to "
       << seconds(w.loops.back().event.stamp, w.start) << " s; each moved the newest keyframe by "
       << formatFixed(shifts[shifts.size() / 2], 3) << " m (median), at most "
       << formatFixed(largest.front().event.shift_m, 3) << " m and " << formatFixed(turn, 2) << " deg"
       << (w.loops.size() > kListedStretches ? "; the largest:" : ":") << "\n\n";
  }
  md << "| at s | loop between keyframes | moved the newest keyframe by |\n| --- | --- | --- |\n";
  auto keyframe = [&](int64_t id, double stamp) {
    return std::to_string(id) + (std::isfinite(stamp) ? " (" + seconds(stamp, w.start) + " s)" : std::string());
  };
  for (size_t i = 0; i < largest.size() && i < kListedStretches; ++i) {
    const LoopMark& l = largest[i];
    md << "| " << seconds(l.event.stamp, w.start) << " | " << keyframe(l.event.from_id, l.from_stamp) << " and "
       << keyframe(l.event.to_id, l.to_stamp) << " | " << formatFixed(l.event.shift_m, 3) << " m, "
       << formatFixed(l.event.turn_deg, 2) << " deg |\n";
  }
  md << "\n";
  if (largest.size() > kListedStretches)
    md << "and " << counted(static_cast<int64_t>(largest.size() - kListedStretches), "smaller one", "smaller ones")
       << ".\n\n";
}

}  // namespace

std::vector<TimeSpan> mergeFlaggedRuns(const std::vector<double>& stamps, const std::vector<bool>& flagged) {
  if (stamps.size() != flagged.size())
    throw std::invalid_argument("mergeFlaggedRuns: " + std::to_string(stamps.size()) + " stamps but " +
                                std::to_string(flagged.size()) + " flags");
  std::vector<TimeSpan> spans;
  bool open = false;
  for (size_t i = 0; i < stamps.size(); ++i) {
    if (!flagged[i]) {
      open = false;
      continue;
    }
    if (!open) spans.push_back({stamps[i], stamps[i], 0});
    open = true;
    spans.back().to = stamps[i];
    ++spans.back().count;
  }
  return spans;
}

std::vector<TimeSpan> longestFirst(std::vector<TimeSpan> spans) {
  std::stable_sort(spans.begin(), spans.end(), longer);
  return spans;
}

WeakAxis weakAxis(const Mat3& position_covariance, const Vec3& velocity, const Mat3& R_W_I) {
  WeakAxis out;
  const Mat3 P = 0.5 * (position_covariance + position_covariance.transpose());
  if (!P.allFinite()) return out;
  const Eigen::SelfAdjointEigenSolver<Mat3> es(P);  // ascending
  const Vec3 l = es.eigenvalues();
  if (!(l[2] > 0.0) || l[2] < kDominance * l[1]) return out;
  const Vec3 e = es.eigenvectors().col(2);
  const Vec3 body = R_W_I.transpose() * e;
  int axis = 0;
  body.cwiseAbs().maxCoeff(&axis);
  out.body_axis = std::abs(body[axis]) >= kCos30 ? axis : -1;
  const double speed = velocity.norm();
  const double along = speed > 0.0 ? std::abs(e.dot(velocity) / speed) : 0.0;
  if (speed >= kAtRestSpeed && along >= kCos30)
    out.direction = WeakDirection::kAlongTravel;
  else if (std::abs(e.z()) >= kCos30)
    out.direction = WeakDirection::kVertical;
  else if (speed < kAtRestSpeed)
    out.direction = WeakDirection::kAtRest;
  else if (along <= 0.5)
    out.direction = WeakDirection::kAcrossTravel;
  else
    out.direction = WeakDirection::kOblique;
  return out;
}

std::string describe(const WeakAxis& a) {
  std::string words;
  switch (a.direction) {
    case WeakDirection::kNoSingle: return "in no single direction";
    case WeakDirection::kAlongTravel: words = "along the direction of travel"; break;
    case WeakDirection::kAcrossTravel: words = "across the direction of travel"; break;
    case WeakDirection::kVertical: words = "vertically"; break;
    case WeakDirection::kOblique: words = "oblique to the direction of travel"; break;
    case WeakDirection::kAtRest: words = "horizontally, at rest"; break;
  }
  if (a.body_axis >= 0) words += std::string(" (body ") + "xyz"[a.body_axis] + ")";
  return words;
}

WeakSpots findWeakSpots(const PipelineOutputs& o, const std::string& camera_channel) {
  WeakSpots w;
  w.sweeps = static_cast<int64_t>(o.odometry.size());
  if (!o.odometry.empty()) w.start = o.odometry.front().stamp;
  const std::vector<double> stamps = stampsOf(o.odometry);

  std::vector<bool> degenerate;
  const std::vector<std::string> words = degenerateDescriptions(o, &degenerate);
  w.degenerate = countOf(degenerate);
  std::vector<std::string> all_words;
  for (size_t i = 0; i < words.size(); ++i)
    if (degenerate[i]) all_words.push_back(words[i]);
  std::tie(w.direction, w.direction_share) = mostFrequent(all_words);
  size_t i = 0;  // walks the sweeps along the stretches (both in time order)
  for (const TimeSpan& s : mergeFlaggedRuns(stamps, degenerate)) {
    while (!degenerate[i]) ++i;
    const std::vector<std::string> in_span(words.begin() + static_cast<std::ptrdiff_t>(i),
                                           words.begin() + static_cast<std::ptrdiff_t>(i + s.count));
    w.degenerate_stretches.push_back({s, mostFrequent(in_span).first});
    i += static_cast<size_t>(s.count);
  }

  const std::vector<bool> predicted = predictedSweeps(o);
  w.predicted = countOf(predicted);
  w.predicted_spans = mergeFlaggedRuns(stamps, predicted);
  w.state_priors = o.state_priors;
  w.visual = visualRefusals(o, camera_channel);
  w.loops = loopMarks(o);
  return w;
}

nlohmann::json weakSpotsJson(const WeakSpots& w) {
  nlohmann::json stretches = nlohmann::json::array();
  for (const DegenerateStretch& d : w.degenerate_stretches) {
    nlohmann::json s = spanJson(d.span);
    s["direction"] = d.direction;
    stretches.push_back(s);
  }
  nlohmann::json visual = nlohmann::json::array();
  for (const VisualRefusals& v : w.visual)
    visual.push_back({{"node", v.node},
                      {"what", v.what},
                      {"refused", v.refused},
                      {"of", v.of},
                      {"reasons", v.reasons},
                      {"spans", spansJson(v.spans)}});
  nlohmann::json loops = nlohmann::json::array();
  for (const LoopMark& l : w.loops)
    loops.push_back({{"correction_id", l.event.correction_id},
                     {"epoch", l.event.epoch},
                     {"time", l.event.stamp},
                     {"from_id", l.event.from_id},
                     {"from_time", l.from_stamp},
                     {"to_id", l.event.to_id},
                     {"to_time", l.to_stamp},
                     {"fitness_m2", l.event.fitness},
                     {"shift_m", l.event.shift_m},
                     {"turn_deg", l.event.turn_deg}});
  return {{"start", w.start},
          {"sweeps", w.sweeps},
          {"degenerate",
           {{"count", w.degenerate},
            {"direction", w.direction},
            {"direction_share", w.direction_share},
            {"spans", stretches}}},
          {"predicted", {{"count", w.predicted}, {"spans", spansJson(w.predicted_spans)}}},
          {"state_priors", w.state_priors},
          {"vio", visual},
          {"loops", loops}};
}

WeakSpots weakSpotsFromJson(const nlohmann::json& j) {
  WeakSpots w;
  w.start = j.at("start").get<double>();
  w.sweeps = j.at("sweeps").get<int64_t>();
  const nlohmann::json& d = j.at("degenerate");
  w.degenerate = d.at("count").get<int64_t>();
  w.direction = d.at("direction").get<std::string>();
  w.direction_share = d.at("direction_share").get<double>();
  for (const auto& s : d.at("spans"))
    w.degenerate_stretches.push_back({spanFrom(s), s.at("direction").get<std::string>()});
  w.predicted = j.at("predicted").at("count").get<int64_t>();
  w.predicted_spans = spansFrom(j.at("predicted").at("spans"));
  w.state_priors = j.at("state_priors").get<int64_t>();
  for (const auto& v : j.at("vio"))
    w.visual.push_back({v.at("node").get<std::string>(), v.at("what").get<std::string>(),
                        v.at("refused").get<int64_t>(), v.at("of").get<int64_t>(),
                        v.at("reasons").get<std::map<std::string, int64_t>>(), spansFrom(v.at("spans"))});
  for (const auto& l : j.at("loops")) {
    LoopMark m;
    m.event.correction_id = l.at("correction_id").get<int64_t>();
    m.event.epoch = l.at("epoch").get<int32_t>();
    m.event.stamp = l.at("time").get<double>();
    m.event.from_id = l.at("from_id").get<int64_t>();
    m.event.to_id = l.at("to_id").get<int64_t>();
    m.event.fitness = numberOrNan(l.at("fitness_m2"));
    m.event.shift_m = numberOrNan(l.at("shift_m"));
    m.event.turn_deg = numberOrNan(l.at("turn_deg"));
    m.from_stamp = numberOrNan(l.at("from_time"));
    m.to_stamp = numberOrNan(l.at("to_time"));
    w.loops.push_back(m);
  }
  return w;
}

std::string weakSpotsMarkdown(const WeakSpots& w) {
  std::ostringstream md;
  md << "## Where the estimate was weak\n\n";
  md << "Times in s since the first odometry pose (`weak_spots.json` has them as stamps; the trajectory "
        "figures mark the degenerate stretches and the loops).\n\n";
  degenerateMarkdown(w, md);
  predictedMarkdown(w, md);
  visualMarkdown(w, md);
  loopMarkdown(w, md);
  return md.str();
}

}  // namespace livo::report
