#include "livo/message_registry.hpp"

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
template <class... Ts>
std::vector<MessageType> listTypes() {
  return {MessageType{std::string("livo.") + Ts::getTypeName(), Ts::getHash()}...};
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
  const auto* b = static_cast<const uint8_t*>(data);
  uint64_t h = 0;
  for (int i = 0; i < 8; ++i) h = (h << 8) | b[i];
  for (const auto& t : messageTypes())
    if (static_cast<uint64_t>(t.fingerprint) == h) return &t;
  return nullptr;
}

}  // namespace livo
