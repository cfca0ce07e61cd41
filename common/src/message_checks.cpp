#include "livo/message_checks.hpp"

#include <cmath>

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

std::string poseProblem(const double position[3], const double q[4]) {
  if (!allFinite(position, 3) || !allFinite(q, 4)) return "pose is not finite";
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(norm >= 0.5 && norm <= 2.0)) return "orientation is not a unit quaternion";
  return "";
}

}  // namespace livo
