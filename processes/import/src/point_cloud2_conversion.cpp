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

DecodeError fieldError(const std::string& where, const std::string& field, const std::string& what) {
  return DecodeError(where + ": field '" + field + "': " + what);
}

/// Livox's fields (offset_time, or tag with line): a solid-state LiDAR's cloud.
bool hasLivoxFields(const RosPointCloud2& m) {
  return find(m, {"offset_time"}) || (find(m, {"tag"}) && find(m, {"line"}));
}

/// The fields the conversion reads.
struct CloudFields {
  Field x, y, z;
  Field intensity, ring, time;
  bool absolute_time = false;  // "timestamp": absolute stamps, else offsets from the header stamp
};

/// Checks that every field lies inside the point and the data holds height * row_step bytes, and
/// finds the fields by name (the time field by `time_field` when given); throws naming the field.
CloudFields findCloudFields(const RosPointCloud2& m, const std::string& time_field, const std::string& where) {
  for (const RosPointField& f : m.fields) {
    if (pointFieldSize(f.datatype) == 0) continue;  // unknown datatype: unused unless named below
    if (static_cast<uint64_t>(f.offset) + pointFieldSize(f.datatype) > m.point_step)
      throw fieldError(where, f.name,
                       "offset " + std::to_string(f.offset) + " + " + typeName(f.datatype) +
                           " lies outside point_step " + std::to_string(m.point_step));
  }
  CloudFields c;
  c.x = find(m, {"x"}), c.y = find(m, {"y"}), c.z = find(m, {"z"});
  for (auto [fld, name] : {std::pair{c.x, "x"}, {c.y, "y"}, {c.z, "z"}}) {
    if (!fld) throw fieldError(where, name, "missing (the cloud has no '" + std::string(name) + "' coordinate field)");
    if (pointFieldSize(fld.f->datatype) == 0)
      throw fieldError(where, name, "unknown datatype " + std::to_string(fld.f->datatype));
  }
  if (m.height > 0 && static_cast<uint64_t>(m.row_step) < static_cast<uint64_t>(m.width) * m.point_step)
    throw fieldError(where, "row_step", std::to_string(m.row_step) + " is less than width * point_step");
  if (static_cast<uint64_t>(m.row_step) * m.height > m.data_size)
    throw fieldError(where, "data",
                     "holds " + std::to_string(m.data_size) + " bytes, height * row_step needs " +
                         std::to_string(static_cast<uint64_t>(m.row_step) * m.height));
  c.intensity = find(m, {"intensity", "reflectivity", "signal"});
  c.ring = find(m, {"ring", "channel", "line"});
  c.time = time_field.empty() ? find(m, {"time", "t", "offset_time", "timestamp"}) : find(m, {time_field.c_str()});
  if (!time_field.empty() && !c.time)
    throw fieldError(where, time_field, "missing (asked for with --lidar-time-field)");
  for (Field f : {c.intensity, c.ring, c.time})
    if (f && pointFieldSize(f.f->datatype) == 0)
      throw fieldError(where, f.f->name, "unknown datatype " + std::to_string(f.f->datatype));
  c.absolute_time = c.time && c.time.f->name == "timestamp";
  return c;
}

/// "x y z intensity ring t(uint32 ns, relative)": the fields read, in that order.
std::string describeLayout(const CloudFields& f, const std::string& time_unit) {
  std::ostringstream layout;
  layout << "x y z";
  if (f.intensity) layout << " " << f.intensity.f->name;
  if (f.ring) layout << " " << f.ring.f->name;
  if (f.time)
    layout << " " << f.time.f->name << "(" << typeName(f.time.f->datatype) << " " << time_unit << ", "
           << (f.absolute_time ? "absolute" : "relative") << ")";
  return layout.str();
}

/// The points with finite, non-zero coordinates, one vector per value, and the counts of the others.
struct CloudColumns {
  std::vector<float> x, y, z, intensity;
  std::vector<int16_t> ring;
  std::vector<uint32_t> place;  // without a time field: column (organised) or index (firing order)
  std::vector<double> times;    // the time field's raw values
  int max_ring = -1;
  int64_t non_finite_points = 0;
  int64_t zero_points = 0;
};

CloudColumns readPoints(const RosPointCloud2& m, const CloudFields& f) {
  const uint64_t points = static_cast<uint64_t>(m.width) * m.height;
  CloudColumns c;
  c.x.reserve(points), c.y.reserve(points), c.z.reserve(points), c.intensity.reserve(points), c.ring.reserve(points);
  if (f.time) c.times.reserve(points);
  for (uint32_t row = 0; row < m.height; ++row) {
    const uint8_t* row_ptr = m.data + static_cast<size_t>(row) * m.row_step;
    for (uint32_t col = 0; col < m.width; ++col) {
      const uint8_t* p = row_ptr + static_cast<size_t>(col) * m.point_step;
      const double x = readValue(p + f.x.f->offset, f.x.f->datatype, m.is_bigendian);
      const double y = readValue(p + f.y.f->offset, f.y.f->datatype, m.is_bigendian);
      const double z = readValue(p + f.z.f->offset, f.z.f->datatype, m.is_bigendian);
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
        ++c.non_finite_points;
        continue;
      }
      if (x == 0.0 && y == 0.0 && z == 0.0) {
        ++c.zero_points;
        continue;
      }
      c.x.push_back(static_cast<float>(x));
      c.y.push_back(static_cast<float>(y));
      c.z.push_back(static_cast<float>(z));
      c.intensity.push_back(f.intensity ? static_cast<float>(readValue(p + f.intensity.f->offset,
                                                                       f.intensity.f->datatype, m.is_bigendian))
                                        : 0.0f);
      int ring = -1;
      if (f.ring) {
        const double rv = readValue(p + f.ring.f->offset, f.ring.f->datatype, m.is_bigendian);
        ring = (rv >= 0.0 && rv <= 32767.0) ? static_cast<int>(rv) : -1;
      } else if (m.height > 1) {
        ring = static_cast<int>(row);  // organised cloud: one row per beam
      }
      c.ring.push_back(static_cast<int16_t>(ring));
      c.max_ring = std::max(c.max_ring, ring);
      if (f.time)
        c.times.push_back(readValue(p + f.time.f->offset, f.time.f->datatype, m.is_bigendian));
      else  // organised: rows are beams, a column is a firing; else the cloud is in firing order
        c.place.push_back(m.height > 1 ? col : row * m.width + col);
    }
  }
  return c;
}

/// The sweep's start (utime, microseconds) and each point's time after it (seconds).
struct SweepTimes {
  int64_t utime = 0;
  std::vector<float> offsets;
  std::string note;  // for the layout: where the times come from when there is no time field
};

/// Times relative to the header stamp, in `scale` seconds: the sweep starts at the earlier of the
/// stamp-derived start `base_ns` and the first point.
SweepTimes relativePointTimes(const std::vector<double>& times, double scale, int64_t stamp_ns, int64_t base_ns,
                              double max_span_s, const std::string& field, const std::string& where) {
  const auto [mn_it, mx_it] = std::minmax_element(times.begin(), times.end());
  const double mn = *mn_it, mx = *mx_it;
  const double span = (mx - mn) * scale;
  if (!(span <= max_span_s))
    throw fieldError(where, field,
                     "per-point times span " + std::to_string(span) +
                         " s, more than a sweep can last: wrong unit? (force one with --lidar-time-unit)");
  // Offsets that go negative can only be relative to the stamp itself (a stamp at the end).
  const int64_t ref_ns = mn < 0.0 ? stamp_ns : base_ns;
  const double first_s = mn * scale;
  SweepTimes out;
  out.utime = floorDiv(ref_ns + std::min<int64_t>(0, static_cast<int64_t>(std::floor(first_s * 1e9))), 1000);
  const double shift = static_cast<double>(ref_ns - out.utime * 1000) * 1e-9;
  out.offsets.resize(times.size());
  for (size_t j = 0; j < times.size(); ++j) out.offsets[j] = static_cast<float>(times[j] * scale + shift);
  return out;
}

/// Absolute point times, in seconds or nanoseconds (whichever lands near the header stamp, unless
/// `time_unit` forces `scale`): the sweep starts at the earlier of `base_ns` and the first point.
SweepTimes absolutePointTimes(const std::vector<double>& times, double scale, int64_t stamp_ns, int64_t base_ns,
                              const PointCloudConversionOptions& o, const std::string& field,
                              const std::string& where) {
  const auto [mn_it, mx_it] = std::minmax_element(times.begin(), times.end());
  const double mn = *mn_it, mx = *mx_it;
  const double stamp_s = static_cast<double>(stamp_ns) * 1e-9;
  double abs_scale = scale;
  if (o.time_unit.empty()) {
    if (std::fabs(mn - stamp_s) < 10.0)
      abs_scale = 1.0;
    else if (std::fabs(mn * 1e-9 - stamp_s) < 10.0)
      abs_scale = 1e-9;
    else
      throw fieldError(where, field,
                       "absolute point time " + std::to_string(mn) +
                           " is neither seconds nor nanoseconds near the header stamp " + std::to_string(stamp_s) +
                           " s: wrong unit?");
  }
  if (!((mx - mn) * abs_scale <= o.max_relative_span_s))
    throw fieldError(where, field, "per-point times span " + std::to_string((mx - mn) * abs_scale) + " s: wrong unit?");
  const int64_t first_ns = static_cast<int64_t>(std::floor(mn * abs_scale * 1e9));
  SweepTimes out;
  out.utime = floorDiv(std::min(base_ns, first_ns), 1000);
  out.offsets.resize(times.size());
  for (size_t j = 0; j < times.size(); ++j)
    out.offsets[j] = static_cast<float>((times[j] - static_cast<double>(out.utime) * 1e-6 / abs_scale) * abs_scale);
  return out;
}

/// A spinning LiDAR's point times from the azimuth (azimuthTimeOffsets), each point placed in the
/// sweep by its column over the width (organised: rows are beams); in firing order, by its column
/// (a run of one point per ring, when the rings are known) over the columns.
std::vector<float> azimuthPointTimes(const RosPointCloud2& m, const CloudColumns& c, double sweep_duration,
                                     bool* clockwise) {
  const uint64_t points = static_cast<uint64_t>(m.width) * m.height;
  const uint32_t rings = m.height > 1 ? 1u : static_cast<uint32_t>(std::max(1, c.max_ring + 1));
  const double columns = m.height > 1 ? m.width : std::ceil(static_cast<double>(points) / rings);
  std::vector<float> order(c.place.size());
  for (size_t j = 0; j < c.place.size(); ++j) order[j] = static_cast<float>((c.place[j] / rings) / columns);
  return azimuthTimeOffsets(c.x, c.y, order, sweep_duration, clockwise);
}

/// The sweep start from the header stamp (and its convention) and the point times: from the time
/// field, else from the azimuth of a spinning LiDAR (unless turned off), else all at the start.
SweepTimes sweepTimes(const RosPointCloud2& m, const CloudFields& f, const CloudColumns& c,
                      const PointCloudConversionOptions& o, double scale, const std::string& where) {
  const int64_t stamp_ns = m.header.stampNs();
  const int64_t duration_ns = std::llround(o.sweep_duration * 1e9);
  const int64_t base_ns = o.stamp == LidarStampConvention::kEnd ? stamp_ns - duration_ns : stamp_ns;
  if (f.time && !c.times.empty())
    return f.absolute_time
               ? absolutePointTimes(c.times, scale, stamp_ns, base_ns, o, f.time.f->name, where)
               : relativePointTimes(c.times, scale, stamp_ns, base_ns, o.max_relative_span_s, f.time.f->name, where);
  SweepTimes out;
  out.utime = floorDiv(base_ns, 1000);
  out.offsets.assign(c.x.size(), 0.0f);
  if (f.time) return out;
  const bool spinning = o.pattern >= 0 ? o.pattern == point_cloud_t::PATTERN_SPINNING : !hasLivoxFields(m);
  if (o.azimuth_times && spinning && c.x.size() > 1) {
    bool clockwise = true;
    out.offsets = azimuthPointTimes(m, c, o.sweep_duration, &clockwise);
    out.note =
        std::string(" (no per-point time: from the azimuth, ") + (clockwise ? "clockwise" : "counter-clockwise") + ")";
  } else {
    out.note = " (no per-point time)";
  }
  return out;
}

point_cloud_t assembleCloud(const RosPointCloud2& m, const CloudFields& f, CloudColumns columns, SweepTimes sweep,
                            const PointCloudConversionOptions& o) {
  point_cloud_t c;
  c.utime = sweep.utime;
  c.frame = o.frame;
  c.pattern = o.pattern >= 0
                  ? static_cast<int8_t>(o.pattern)
                  : (hasLivoxFields(m) ? point_cloud_t::PATTERN_SOLID_STATE : point_cloud_t::PATTERN_SPINNING);
  c.num_rings =
      static_cast<int16_t>(o.num_rings > 0 ? o.num_rings : (m.height > 1 && !f.ring ? m.height : columns.max_ring + 1));
  float max_offset = 0.0f;
  for (float t : sweep.offsets) max_offset = std::max(max_offset, t);
  c.sweep_duration = static_cast<float>(o.sweep_duration);
  if (max_offset >= c.sweep_duration) c.sweep_duration = std::nextafter(max_offset, 1e9f);
  c.num_points = static_cast<int32_t>(columns.x.size());
  c.x = std::move(columns.x);
  c.y = std::move(columns.y);
  c.z = std::move(columns.z);
  c.intensity = std::move(columns.intensity);
  c.time_offset = std::move(sweep.offsets);
  c.ring = std::move(columns.ring);
  return c;
}

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
  const CloudFields fields = findCloudFields(m, o.time_field, where);
  std::string unit;
  double scale = 1.0;
  if (fields.time) {
    unit = !o.time_unit.empty() ? o.time_unit : (isInteger(fields.time.f->datatype) ? "ns" : "s");
    scale = unitScale(unit, where, fields.time.f->name);
  }
  CloudColumns columns = readPoints(m, fields);
  SweepTimes sweep = sweepTimes(m, fields, columns, o, scale, where);
  PointCloudConversion out;
  out.non_finite_points = columns.non_finite_points;
  out.zero_points = columns.zero_points;
  out.layout = describeLayout(fields, unit) + sweep.note;
  out.cloud = assembleCloud(m, fields, std::move(columns), std::move(sweep), o);
  return out;
}

}  // namespace livo::import
