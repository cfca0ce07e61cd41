#include "livo/message_registry.hpp"

#include <cmath>
#include <type_traits>

#include "livo/channel_stats_t.hpp"
#include "livo/colored_cloud_t.hpp"
#include "livo/filter_state_t.hpp"
#include "livo/health_t.hpp"
#include "livo/image_t.hpp"
#include "livo/imu_t.hpp"
#include "livo/keyframe_t.hpp"
#include "livo/loop_correction_t.hpp"
#include "livo/octomap_t.hpp"
#include "livo/odometry_t.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/pose_t.hpp"
#include "livo/progress_t.hpp"
#include "livo/registered_scan_t.hpp"
#include "livo/visual_state_t.hpp"
#include "livo/wheel_odometry_t.hpp"

namespace livo {

namespace {
// True if T's first field is `int64_t utime` (checked by encoding a message with a marker).
template <class T>
bool leadsWithUtime() {
  if constexpr (std::is_same_v<decltype(T::utime), int64_t>) {
    T m{};
    m.utime = 0x0102030405060708LL;
    std::vector<uint8_t> buf(m.getEncodedSize());
    m.encode(buf.data(), 0, static_cast<int>(buf.size()));
    return buf.size() >= 16 && buf[8] == 1 && buf[15] == 8;
  } else {
    return false;
  }
}

template <class T, class = void>
struct HasUtime : std::false_type {};
template <class T>
struct HasUtime<T, std::void_t<decltype(T::utime)>> : std::true_type {};

template <class T>
bool leadingUtime() {
  if constexpr (HasUtime<T>::value) return leadsWithUtime<T>();
  return false;
}

template <class... Ts>
std::vector<MessageType> listTypes() {
  return {MessageType{std::string("livo.") + Ts::getTypeName(), Ts::getHash(), leadingUtime<Ts>()}...};
}

uint64_t readBigEndian64(const uint8_t* b) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | b[i];
  return v;
}
}  // namespace

const std::vector<MessageType>& messageTypes() {
  static const std::vector<MessageType> types =
      listTypes<imu_t, point_cloud_t, image_t, wheel_odometry_t, pose_t, odometry_t, filter_state_t, registered_scan_t,
                keyframe_t, loop_correction_t, colored_cloud_t, octomap_t, progress_t, channel_stats_t, health_t,
                visual_state_t>();
  return types;
}

const MessageType* identifyMessage(const void* data, int size) {
  if (size < 8) return nullptr;
  const uint64_t h = readBigEndian64(static_cast<const uint8_t*>(data));
  for (const auto& t : messageTypes())
    if (static_cast<uint64_t>(t.fingerprint) == h) return &t;
  return nullptr;
}

}  // namespace livo

namespace livo {

bool messageUtime(const void* data, int size, int64_t* utime) {
  const MessageType* t = identifyMessage(data, size);
  if (!t || !t->leading_utime || size < 16) return false;
  *utime = static_cast<int64_t>(readBigEndian64(static_cast<const uint8_t*>(data) + 8));
  return true;
}

bool setMessageUtime(void* data, int size, int64_t utime) {
  const MessageType* t = identifyMessage(data, size);
  if (!t || !t->leading_utime || size < 16) return false;
  auto* b = static_cast<uint8_t*>(data) + 8;
  uint64_t u = static_cast<uint64_t>(utime);
  for (int i = 7; i >= 0; --i, u >>= 8) b[i] = static_cast<uint8_t>(u & 0xff);
  return true;
}

}  // namespace livo

namespace livo {

namespace {
int64_t nonFinite(double v) { return std::isfinite(v) ? 0 : 1; }
int64_t nonFinite(float v) { return std::isfinite(v) ? 0 : 1; }
template <class Range>
int64_t nonFinite(const Range& values) {
  int64_t n = 0;
  for (const auto& v : values) n += nonFinite(v);
  return n;
}
template <class T, size_t N>
int64_t nonFinite(const T (&values)[N]) {
  int64_t n = 0;
  for (const auto& v : values) n += nonFinite(static_cast<double>(v));
  return n;
}

int64_t nonFiniteIn(const point_cloud_t& m) {
  return nonFinite(m.sweep_duration) + nonFinite(m.x) + nonFinite(m.y) + nonFinite(m.z) + nonFinite(m.intensity) +
         nonFinite(m.time_offset);
}
int64_t nonFiniteIn(const imu_t& m) { return nonFinite(m.angular_velocity) + nonFinite(m.linear_acceleration); }
int64_t nonFiniteIn(const pose_t& m) { return nonFinite(m.position) + nonFinite(m.orientation); }
int64_t nonFiniteIn(const wheel_odometry_t& m) { return nonFinite(m.left_speed) + nonFinite(m.right_speed); }
int64_t nonFiniteIn(const image_t& m) { return nonFinite(m.exposure_time); }
int64_t nonFiniteIn(const odometry_t& m) {
  return nonFinite(m.position) + nonFinite(m.orientation) + nonFinite(m.velocity) + nonFinite(m.angular_velocity) +
         nonFinite(m.pose_covariance) + nonFinite(m.velocity_covariance) + nonFinite(m.min_information_eigenvalue);
}
int64_t nonFiniteIn(const filter_state_t& m) {
  return nonFinite(m.orientation) + nonFinite(m.position) + nonFinite(m.velocity) + nonFinite(m.gyro_bias) +
         nonFinite(m.accel_bias) + nonFinite(m.gravity) + nonFinite(m.covariance);
}
int64_t nonFiniteIn(const registered_scan_t& m) {
  return nonFinite(m.position) + nonFinite(m.orientation) + nonFiniteIn(m.cloud);
}
int64_t nonFiniteIn(const keyframe_t& m) {
  return nonFinite(m.position) + nonFinite(m.orientation) + nonFinite(m.pose_covariance) +
         nonFinite(m.relative_covariance) + nonFinite(m.relative_covariance_held_calibration) + nonFiniteIn(m.cloud);
}
int64_t nonFiniteIn(const loop_correction_t& m) {
  int64_t n = nonFinite(m.loop_fitness) + nonFinite(m.correction_position) + nonFinite(m.correction_orientation);
  for (const auto& p : m.position) n += nonFinite(p);
  for (const auto& q : m.orientation) n += nonFinite(q);
  return n;
}
int64_t nonFiniteIn(const visual_state_t& m) {
  return nonFinite(m.position) + nonFinite(m.orientation) + nonFinite(m.velocity) + nonFinite(m.gyro_bias) +
         nonFinite(m.accel_bias) + nonFinite(m.pose_covariance);
}
int64_t nonFiniteIn(const colored_cloud_t& m) { return nonFinite(m.x) + nonFinite(m.y) + nonFinite(m.z); }
int64_t nonFiniteIn(const octomap_t& m) { return nonFinite(m.resolution); }
int64_t nonFiniteIn(const channel_stats_t& m) {
  return nonFinite(m.median_ms) + nonFinite(m.p90_ms) + nonFinite(m.max_ms);
}
int64_t nonFiniteIn(const health_t& m) {
  int64_t n = nonFinite(m.peak_rss_mb);
  for (const auto& c : m.channels) n += nonFiniteIn(c);
  return n;
}
int64_t nonFiniteIn(const progress_t&) { return 0; }

template <class T>
int64_t decodeAndCount(const void* data, int size) {
  T m{};
  if (m.decode(data, 0, size) != size) return -1;
  return nonFiniteIn(m);
}

template <class... Ts>
int64_t countFor(const void* data, int size) {
  const uint64_t h = readBigEndian64(static_cast<const uint8_t*>(data));
  int64_t result = -1;
  ((static_cast<uint64_t>(Ts::getHash()) == h ? (result = decodeAndCount<Ts>(data, size), true) : false) || ...);
  return result;
}
}  // namespace

int64_t countNonFinite(const void* data, int size) {
  if (size < 8) return -1;
  return countFor<imu_t, point_cloud_t, image_t, wheel_odometry_t, pose_t, odometry_t, filter_state_t,
                  registered_scan_t, keyframe_t, loop_correction_t, colored_cloud_t, octomap_t, progress_t,
                  channel_stats_t, health_t, visual_state_t>(data, size);
}

}  // namespace livo
