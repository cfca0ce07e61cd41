#include "livo/playback/fault_injector.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "livo/message_registry.hpp"
#include "livo/point_cloud_t.hpp"

namespace livo::playback {

namespace {

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, sep)) out.push_back(item);
  return out;
}

double number(const std::string& s, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !std::isfinite(v))
    throw std::invalid_argument("fault '" + text + "': '" + s + "' is not a number");
  return v;
}

double fractionOf(const std::string& s, const std::string& text) {
  const double f = number(s, text);
  if (f < 0.0 || f > 1.0) throw std::invalid_argument("fault '" + text + "': fraction must be in [0, 1]");
  return f;
}

}  // namespace

Fault parseFault(const std::string& text) {
  const auto p = split(text, ':');
  if (p.size() < 3 || p[1].empty()) throw std::invalid_argument("fault '" + text + "': expected KIND:CHANNEL:...");
  Fault f;
  f.channel = p[1];
  const std::string& k = p[0];
  auto need = [&](size_t n, const char* form) {
    if (p.size() != n) throw std::invalid_argument("fault '" + text + "': expected " + form);
  };
  if (k == "drop" || k == "duplicate" || k == "reorder" || k == "corrupt" || k == "nan") {
    need(3, (k + ":CHANNEL:FRACTION").c_str());
    f.kind = k == "drop"        ? Fault::Kind::kDrop
             : k == "duplicate" ? Fault::Kind::kDuplicate
             : k == "reorder"   ? Fault::Kind::kReorder
             : k == "corrupt"   ? Fault::Kind::kCorrupt
                                : Fault::Kind::kNanPoints;
    f.fraction = fractionOf(p[2], text);
  } else if (k == "delay") {
    need(4, "delay:CHANNEL:FRACTION:SECONDS");
    f.kind = Fault::Kind::kDelay;
    f.fraction = fractionOf(p[2], text);
    f.seconds = number(p[3], text);
    if (f.seconds <= 0) throw std::invalid_argument("fault '" + text + "': delay must be positive");
  } else if (k == "jump") {
    need(4, "jump:CHANNEL:AT_SECONDS:JUMP_SECONDS");
    f.kind = Fault::Kind::kTimeJump;
    f.from_s = number(p[2], text);
    f.seconds = number(p[3], text);
  } else if (k == "cut") {
    need(4, "cut:CHANNEL:FROM_SECONDS:TO_SECONDS");
    f.kind = Fault::Kind::kCut;
    f.from_s = number(p[2], text);
    f.to_s = number(p[3], text);
    if (f.to_s <= f.from_s) throw std::invalid_argument("fault '" + text + "': the window must end after it starts");
  } else {
    throw std::invalid_argument("fault '" + text + "': unknown kind '" + k +
                                "' (drop, duplicate, delay, reorder, corrupt, nan, jump, cut)");
  }
  return f;
}

std::string describe(const Fault& f) {
  std::ostringstream os;
  switch (f.kind) {
    case Fault::Kind::kDrop: os << "drop " << f.fraction * 100 << "% of " << f.channel; break;
    case Fault::Kind::kDuplicate: os << "duplicate " << f.fraction * 100 << "% of " << f.channel; break;
    case Fault::Kind::kDelay:
      os << "delay " << f.fraction * 100 << "% of " << f.channel << " by " << f.seconds << " s";
      break;
    case Fault::Kind::kReorder: os << "swap " << f.fraction * 100 << "% of " << f.channel << " with the next"; break;
    case Fault::Kind::kCorrupt: os << "corrupt bytes of " << f.fraction * 100 << "% of " << f.channel; break;
    case Fault::Kind::kNanPoints: os << "NaN points in " << f.fraction * 100 << "% of " << f.channel; break;
    case Fault::Kind::kTimeJump:
      os << "stamps of " << f.channel << " jump by " << f.seconds << " s at " << f.from_s << " s";
      break;
    case Fault::Kind::kCut: os << "cut " << f.channel << " from " << f.from_s << " s to " << f.to_s << " s"; break;
  }
  return os.str();
}

bool shiftMessageUtime(std::vector<uint8_t>& data, int64_t delta_us) {
  int64_t utime = 0;
  const int size = static_cast<int>(data.size());
  return messageUtime(data.data(), size, &utime) && setMessageUtime(data.data(), size, utime + delta_us);
}

FaultInjector::FaultInjector(std::vector<Fault> faults, uint64_t seed) : faults_(std::move(faults)), rng_(seed) {}

bool FaultInjector::draw(double fraction) {
  // Always consume one number so the decision sequence depends only on the message sequence.
  const double u = std::uniform_real_distribution<double>(0.0, 1.0)(rng_);
  return u < fraction;
}

void FaultInjector::corrupt(LogEvent& e) {
  if (e.data.empty()) return;
  // Flip 1..8 bytes at random positions, including the fingerprint now and then.
  const int n = 1 + static_cast<int>(rng_() % 8);
  for (int i = 0; i < n; ++i) e.data[rng_() % e.data.size()] ^= static_cast<uint8_t>(1 + rng_() % 255);
}

bool FaultInjector::makeNanPoints(LogEvent& e) {
  point_cloud_t c;
  if (c.decode(e.data.data(), 0, static_cast<int>(e.data.size())) != static_cast<int>(e.data.size())) return false;
  if (c.num_points == 0) return false;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // A tenth of the points, at random, get NaN in one or all coordinates.
  for (int i = 0; i < c.num_points; ++i) {
    if (rng_() % 10 != 0) continue;
    switch (rng_() % 4) {
      case 0: c.x[i] = nan; break;
      case 1: c.y[i] = nan; break;
      case 2: c.z[i] = nan; break;
      default: c.x[i] = c.y[i] = c.z[i] = nan;
    }
  }
  e.data.resize(c.getEncodedSize());
  c.encode(e.data.data(), 0, static_cast<int>(e.data.size()));
  return true;
}

std::vector<LogEvent> FaultInjector::push(LogEvent event, int64_t t0) {
  // Release delayed events whose time has come (before this one, by stamp).
  std::vector<LogEvent> out = releaseDelayed(event.utime);
  FaultCounts& counts = counts_[event.channel];
  const double t = (event.utime - t0) * 1e-6;
  const FaultDecision decision = applyFaults(event, t, counts);
  if (!decision.emit) {
    // A dropped or cut message is gone; count it once under the reason that applied first.
    (inCut(event.channel, t) ? counts.cut : counts.dropped)++;
    return out;
  }
  std::vector<LogEvent> now;
  now.push_back(event);
  if (decision.duplicate) {
    now.push_back(event);
    ++counts.duplicated;
  }
  for (LogEvent& e : route(std::move(now), decision, counts)) out.push_back(std::move(e));
  return out;
}

std::vector<LogEvent> FaultInjector::releaseDelayed(int64_t utime) {
  std::vector<LogEvent> out;
  while (!delayed_.empty() && delayed_.top().release_utime <= utime) {
    out.push_back(delayed_.top().event);
    delayed_.pop();
  }
  return out;
}

FaultInjector::FaultDecision FaultInjector::applyFaults(LogEvent& event, double t, FaultCounts& counts) {
  FaultDecision d;
  for (const Fault& f : faults_) {
    if (f.channel != event.channel) continue;
    switch (f.kind) {
      case Fault::Kind::kCut:
        if (t >= f.from_s && t < f.to_s) d.emit = false;
        break;
      case Fault::Kind::kDrop:
        if (draw(f.fraction)) d.emit = false;
        break;
      case Fault::Kind::kDuplicate:
        if (draw(f.fraction)) d.duplicate = true;
        break;
      case Fault::Kind::kDelay:
        if (draw(f.fraction)) d.delay_us = static_cast<int64_t>(std::llround(f.seconds * 1e6));
        break;
      case Fault::Kind::kReorder:
        if (draw(f.fraction)) d.hold = true;
        break;
      case Fault::Kind::kCorrupt:
        if (draw(f.fraction)) {
          corrupt(event);
          ++counts.corrupted;
        }
        break;
      case Fault::Kind::kNanPoints:
        if (draw(f.fraction) && makeNanPoints(event)) ++counts.nan_clouds;
        break;
      case Fault::Kind::kTimeJump:
        if (t >= f.from_s && shiftMessageUtime(event.data, static_cast<int64_t>(std::llround(f.seconds * 1e6)))) {
          ++counts.time_shifted;
        }
        break;
    }
  }
  return d;
}

bool FaultInjector::inCut(const std::string& channel, double t) const {
  bool in_cut = false;
  for (const Fault& f : faults_)
    if (f.channel == channel && f.kind == Fault::Kind::kCut && t >= f.from_s && t < f.to_s) in_cut = true;
  return in_cut;
}

std::vector<LogEvent> FaultInjector::route(std::vector<LogEvent> now, const FaultDecision& decision,
                                           FaultCounts& counts) {
  std::vector<LogEvent> out;
  bool hold = decision.hold;
  for (LogEvent& e : now) {
    if (decision.delay_us > 0) {
      ++counts.delayed;
      const int64_t release = e.utime + decision.delay_us;
      delayed_.push(Delayed{release, order_++, std::move(e)});
      continue;
    }
    auto held = held_.find(e.channel);
    if (held != held_.end()) {
      // the held message goes out right after the one that followed it
      out.push_back(std::move(e));
      out.push_back(std::move(held->second));
      held_.erase(held);
      continue;
    }
    if (hold) {
      ++counts.reordered;
      held_.emplace(e.channel, std::move(e));
      hold = false;
      continue;
    }
    out.push_back(std::move(e));
  }
  return out;
}

std::vector<LogEvent> FaultInjector::flush() {
  std::vector<LogEvent> out;
  for (auto& [ch, e] : held_) out.push_back(std::move(e));
  held_.clear();
  while (!delayed_.empty()) {
    out.push_back(delayed_.top().event);
    delayed_.pop();
  }
  return out;
}

}  // namespace livo::playback
