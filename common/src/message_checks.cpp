#include "livo/message_checks.hpp"

#include "livo/messages.hpp"

namespace livo {

std::string registeredScanProblem(const registered_scan_t& m) {
  const point_cloud_t& c = m.cloud;
  if (c.num_points <= 0) return "empty cloud";
  const size_t n = static_cast<size_t>(c.num_points);
  if (c.x.size() != n || c.y.size() != n || c.z.size() != n || c.time_offset.size() != n)
    return "cloud arrays disagree with num_points";
  if (!allFinite(m.position, 3) || !allFinite(m.orientation, 4)) return "pose is not finite";
  if (!c.frame.empty() && c.frame != "W") return "cloud frame is '" + c.frame + "', expected W";
  return "";
}

}  // namespace livo
