#include "livo/import/point_cloud2_conversion.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

namespace livo::import {

namespace {

const char* typeName(uint8_t t) {
  static const char* names[] = {"?", "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};
  return t <= 8 ? names[t] : "?";
}

bool isInteger(uint8_t t) { return t >= 1 && t <= 6; }

/// One field's value at `p` as double.
double readValue(const uint8_t* p, uint8_t type, bool big_endian) {
  uint8_t b[8];
  const int n = pointFieldSize(type);
  if (big_endian)
    for (int i = 0; i < n; ++i) b[i] = p[n - 1 - i];
  else
    std::memcpy(b, p, n);
  switch (type) {
    case 1: {
      int8_t v;
      std::memcpy(&v, b, 1);
      return v;
    }
    case 2: {
      uint8_t v;
      std::memcpy(&v, b, 1);
      return v;
    }
    case 3: {
      int16_t v;
      std::memcpy(&v, b, 2);
      return v;
    }
    case 4: {
      uint16_t v;
      std::memcpy(&v, b, 2);
      return v;
    }
    case 5: {
      int32_t v;
      std::memcpy(&v, b, 4);
      return v;
    }
    case 6: {
      uint32_t v;
      std::memcpy(&v, b, 4);
      return v;
    }
    case 7: {
      float v;
      std::memcpy(&v, b, 4);
      return v;
    }
    case 8: {
      double v;
      std::memcpy(&v, b, 8);
      return v;
    }
    default: return std::numeric_limits<double>::quiet_NaN();
  }
}

struct Field {
  const RosPointField* f = nullptr;
  explicit operator bool() const { return f != nullptr; }
};

Field find(const RosPointCloud2& m, std::initializer_list<const char*> names) {
  for (const char* n : names)
    for (const RosPointField& f : m.fields)
      if (f.name == n) return Field{&f};
  return Field{};
}

double unitScale(const std::string& unit, const std::string& where, const std::string& field) {
  if (unit == "s") return 1.0;
  if (unit == "ms") return 1e-3;
  if (unit == "us") return 1e-6;
  if (unit == "ns") return 1e-9;
  throw DecodeError(where + ": field '" + field + "': unknown time unit '" + unit + "' (s, ms, us or ns)");
}

int64_t floorDiv(int64_t a, int64_t b) { return a / b - ((a % b != 0) && ((a < 0) != (b < 0))); }

}  // namespace

std::vector<float> azimuthTimeOffsets(const std::vector<float>& x, const std::vector<float>& y,
                                      const std::vector<float>& order, double sweep_duration, bool* clockwise) {
  std::vector<float> out(x.size(), 0.0f);
  if (x.empty()) return out;
  constexpr double kTurn = 2.0 * M_PI;
  auto wrapPi = [&](double a) { return a - kTurn * std::floor((a + M_PI) / kTurn); };  // [-pi, pi)
  std::vector<double> az(x.size());
  for (size_t i = 0; i < x.size(); ++i) az[i] = std::atan2(double(y[i]), double(x[i]));
  // the net turn along the points' order: negative = clockwise seen from above (azimuth falls)
  double turn = 0.0;
  for (size_t i = 1; i < az.size(); ++i) turn += wrapPi(az[i] - az[i - 1]);
  const double dir = turn <= 0.0 ? -1.0 : 1.0;
  if (clockwise) *clockwise = dir < 0.0;
  // where the sweep starts: the circular mean of the first column's azimuths, each taken back by
  // its place (a mean over the beams, so a beam staggered in azimuth does not set the start)
  const float first = *std::min_element(order.begin(), order.end());
  double sum_cos = 0.0, sum_sin = 0.0;
  for (size_t i = 0; i < az.size(); ++i)
    if (order[i] == first) {
      const double a = az[i] - dir * kTurn * order[i];
      sum_cos += std::cos(a), sum_sin += std::sin(a);
    }
  const double start = std::atan2(sum_sin, sum_cos);
  const float last = std::nextafter(static_cast<float>(sweep_duration), 0.0f);
  for (size_t i = 0; i < az.size(); ++i) {
    double fraction = dir * (az[i] - start) / kTurn;
    fraction -= std::floor(fraction);  // [0, 1)
    // the turn it belongs to, from its place in the order: a point a hair behind the start (the
    // first column's stagger, float rounding) is at the start, not at the end, and the reverse
    if (fraction - order[i] > 0.5) fraction = 0.0;
    if (order[i] - fraction > 0.5) fraction = 1.0;
    out[i] = std::min(static_cast<float>(fraction * sweep_duration), last);
  }
  return out;
}

PointCloudConversion convertPointCloud2(const RosPointCloud2& m, const PointCloudConversionOptions& o,
                                        const std::string& where) {
  auto fail = [&](const std::string& field, const std::string& what) -> DecodeError {
    return DecodeError(where + ": field '" + field + "': " + what);
  };
  // Validate the layout.
  for (const RosPointField& f : m.fields) {
    if (pointFieldSize(f.datatype) == 0) continue;  // unknown datatype: unused unless named below
    if (static_cast<uint64_t>(f.offset) + pointFieldSize(f.datatype) > m.point_step)
      throw fail(f.name, "offset " + std::to_string(f.offset) + " + " + typeName(f.datatype) +
                             " lies outside point_step " + std::to_string(m.point_step));
  }
  const Field fx = find(m, {"x"}), fy = find(m, {"y"}), fz = find(m, {"z"});
  for (auto [fld, name] : {std::pair{fx, "x"}, {fy, "y"}, {fz, "z"}}) {
    if (!fld) throw fail(name, "missing (the cloud has no '" + std::string(name) + "' coordinate field)");
    if (pointFieldSize(fld.f->datatype) == 0) throw fail(name, "unknown datatype " + std::to_string(fld.f->datatype));
  }
  const uint64_t points = static_cast<uint64_t>(m.width) * m.height;
  if (m.height > 0 && static_cast<uint64_t>(m.row_step) < static_cast<uint64_t>(m.width) * m.point_step)
    throw fail("row_step", std::to_string(m.row_step) + " is less than width * point_step");
  if (static_cast<uint64_t>(m.row_step) * m.height > m.data_size)
    throw fail("data", "holds " + std::to_string(m.data_size) + " bytes, height * row_step needs " +
                           std::to_string(static_cast<uint64_t>(m.row_step) * m.height));
  const Field fi = find(m, {"intensity", "reflectivity", "signal"});
  const Field fr = find(m, {"ring", "channel", "line"});
  Field ft =
      o.time_field.empty() ? find(m, {"time", "t", "offset_time", "timestamp"}) : find(m, {o.time_field.c_str()});
  if (!o.time_field.empty() && !ft) throw fail(o.time_field, "missing (asked for with --lidar-time-field)");
  for (Field f : {fi, fr, ft})
    if (f && pointFieldSize(f.f->datatype) == 0)
      throw fail(f.f->name, "unknown datatype " + std::to_string(f.f->datatype));
  const bool absolute_time = ft && ft.f->name == "timestamp";

  PointCloudConversion out;
  std::ostringstream layout;
  layout << "x y z";
  if (fi) layout << " " << fi.f->name;
  if (fr) layout << " " << fr.f->name;

  // Per-point values first, then the time reference.
  std::vector<float> xs, ys, zs, is;
  std::vector<int16_t> rings;
  std::vector<uint32_t> place;  // without a time field: column (organised) or index (firing order)
  std::vector<double> times;    // raw time values, scaled to seconds (relative) or kept (absolute)
  xs.reserve(points), ys.reserve(points), zs.reserve(points), is.reserve(points), rings.reserve(points);
  double scale = 1.0;
  if (ft) {
    const std::string unit = !o.time_unit.empty() ? o.time_unit : (isInteger(ft.f->datatype) ? "ns" : "s");
    scale = unitScale(unit, where, ft.f->name);
    layout << " " << ft.f->name << "(" << typeName(ft.f->datatype) << " " << unit << ", "
           << (absolute_time ? "absolute" : "relative") << ")";
    times.reserve(points);
  }
  int max_ring = -1;
  for (uint32_t row = 0; row < m.height; ++row) {
    const uint8_t* row_ptr = m.data + static_cast<size_t>(row) * m.row_step;
    for (uint32_t col = 0; col < m.width; ++col) {
      const uint8_t* p = row_ptr + static_cast<size_t>(col) * m.point_step;
      const double x = readValue(p + fx.f->offset, fx.f->datatype, m.is_bigendian);
      const double y = readValue(p + fy.f->offset, fy.f->datatype, m.is_bigendian);
      const double z = readValue(p + fz.f->offset, fz.f->datatype, m.is_bigendian);
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
        ++out.non_finite_points;
        continue;
      }
      if (x == 0.0 && y == 0.0 && z == 0.0) {
        ++out.zero_points;
        continue;
      }
      xs.push_back(static_cast<float>(x));
      ys.push_back(static_cast<float>(y));
      zs.push_back(static_cast<float>(z));
      is.push_back(fi ? static_cast<float>(readValue(p + fi.f->offset, fi.f->datatype, m.is_bigendian)) : 0.0f);
      int ring = -1;
      if (fr) {
        const double rv = readValue(p + fr.f->offset, fr.f->datatype, m.is_bigendian);
        ring = (rv >= 0.0 && rv <= 32767.0) ? static_cast<int>(rv) : -1;
      } else if (m.height > 1) {
        ring = static_cast<int>(row);  // organised cloud: one row per beam
      }
      rings.push_back(static_cast<int16_t>(ring));
      max_ring = std::max(max_ring, ring);
      if (ft)
        times.push_back(readValue(p + ft.f->offset, ft.f->datatype, m.is_bigendian));
      else  // organised: rows are beams, a column is a firing; else the cloud is in firing order
        place.push_back(m.height > 1 ? col : row * m.width + col);
    }
  }

  const int64_t stamp_ns = m.header.stampNs();
  const int64_t duration_ns = std::llround(o.sweep_duration * 1e9);
  const int64_t base_ns = o.stamp == LidarStampConvention::kEnd ? stamp_ns - duration_ns : stamp_ns;
  std::vector<float> offsets(xs.size(), 0.0f);
  int64_t utime = floorDiv(base_ns, 1000);
  if (ft && !times.empty()) {
    const auto [mn_it, mx_it] = std::minmax_element(times.begin(), times.end());
    const double mn = *mn_it, mx = *mx_it;
    if (!absolute_time) {
      const double span = (mx - mn) * scale;
      if (!(span <= o.max_relative_span_s))
        throw fail(ft.f->name, "per-point times span " + std::to_string(span) +
                                   " s, more than a sweep can last: wrong unit? (force one with --lidar-time-unit)");
      // Offsets that go negative can only be relative to the stamp itself (a stamp at the end).
      const int64_t ref_ns = mn < 0.0 ? stamp_ns : base_ns;
      const double first_s = mn * scale;
      utime = floorDiv(ref_ns + std::min<int64_t>(0, static_cast<int64_t>(std::floor(first_s * 1e9))), 1000);
      const double shift = static_cast<double>(ref_ns - utime * 1000) * 1e-9;
      for (size_t j = 0; j < times.size(); ++j) offsets[j] = static_cast<float>(times[j] * scale + shift);
    } else {
      // Absolute stamps: seconds or nanoseconds, whichever lands near the header stamp.
      const double stamp_s = static_cast<double>(stamp_ns) * 1e-9;
      double abs_scale = scale;
      if (o.time_unit.empty()) {
        if (std::fabs(mn - stamp_s) < 10.0)
          abs_scale = 1.0;
        else if (std::fabs(mn * 1e-9 - stamp_s) < 10.0)
          abs_scale = 1e-9;
        else
          throw fail(ft.f->name, "absolute point time " + std::to_string(mn) +
                                     " is neither seconds nor nanoseconds near the header stamp " +
                                     std::to_string(stamp_s) + " s: wrong unit?");
      }
      if (!((mx - mn) * abs_scale <= o.max_relative_span_s))
        throw fail(ft.f->name, "per-point times span " + std::to_string((mx - mn) * abs_scale) + " s: wrong unit?");
      const int64_t first_ns = static_cast<int64_t>(std::floor(mn * abs_scale * 1e9));
      utime = floorDiv(std::min(base_ns, first_ns), 1000);
      for (size_t j = 0; j < times.size(); ++j)
        offsets[j] = static_cast<float>((times[j] - static_cast<double>(utime) * 1e-6 / abs_scale) * abs_scale);
    }
  } else if (!ft) {
    const bool spinning = o.pattern >= 0 ? o.pattern == point_cloud_t::PATTERN_SPINNING
                                         : !(find(m, {"offset_time"}) || (find(m, {"tag"}) && find(m, {"line"})));
    if (o.azimuth_times && spinning && xs.size() > 1) {
      // the place of a point in the sweep, 0..1: its column over the width (organised: rows are
      // beams); in firing order, its column (a run of one point per ring, when the rings are known)
      // over the columns
      const uint32_t rings = m.height > 1 ? 1u : static_cast<uint32_t>(std::max(1, max_ring + 1));
      const double columns = m.height > 1 ? m.width : std::ceil(static_cast<double>(points) / rings);
      std::vector<float> order(place.size());
      for (size_t j = 0; j < place.size(); ++j) order[j] = static_cast<float>((place[j] / rings) / columns);
      bool clockwise = true;
      offsets = azimuthTimeOffsets(xs, ys, order, o.sweep_duration, &clockwise);
      layout << " (no per-point time: from the azimuth, " << (clockwise ? "clockwise" : "counter-clockwise") << ")";
    } else {
      layout << " (no per-point time)";
    }
  }

  point_cloud_t& c = out.cloud;
  c.utime = utime;
  c.frame = o.frame;
  const bool livox = find(m, {"offset_time"}) || (find(m, {"tag"}) && find(m, {"line"}));
  c.pattern = o.pattern >= 0 ? static_cast<int8_t>(o.pattern)
                             : (livox ? point_cloud_t::PATTERN_SOLID_STATE : point_cloud_t::PATTERN_SPINNING);
  c.num_rings = static_cast<int16_t>(o.num_rings > 0 ? o.num_rings : (m.height > 1 && !fr ? m.height : max_ring + 1));
  float max_offset = 0.0f;
  for (float t : offsets) max_offset = std::max(max_offset, t);
  c.sweep_duration = static_cast<float>(o.sweep_duration);
  if (max_offset >= c.sweep_duration) c.sweep_duration = std::nextafter(max_offset, 1e9f);
  c.num_points = static_cast<int32_t>(xs.size());
  c.x = std::move(xs);
  c.y = std::move(ys);
  c.z = std::move(zs);
  c.intensity = std::move(is);
  c.time_offset = std::move(offsets);
  c.ring = std::move(rings);
  out.layout = layout.str();
  return out;
}

}  // namespace livo::import
