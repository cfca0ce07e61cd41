#include "livo/message_registry.hpp"

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
      listTypes<imu_t, point_cloud_t, image_t, wheel_odometry_t, pose_t, odometry_t, filter_state_t,
                registered_scan_t, keyframe_t, loop_correction_t, colored_cloud_t, octomap_t, progress_t,
                channel_stats_t, health_t>();
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
