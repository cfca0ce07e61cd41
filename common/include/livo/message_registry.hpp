// Every LCM type of the project, looked up by the fingerprint that starts each encoded message.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace livo {

struct MessageType {
  std::string name;     // package-qualified, e.g. "livo.point_cloud_t"
  int64_t fingerprint;  // the 8 bytes every encoded message starts with
  bool leading_utime;   // its first field is `int64_t utime` (bytes 8..15, big-endian)
};

/// All project types.
const std::vector<MessageType>& messageTypes();

/// The type whose fingerprint starts `data`, or nullptr.
const MessageType* identifyMessage(const void* data, int size);

/// How many floating-point values of an encoded project message are not finite (NaN, inf), or -1
/// if it is not a project message or does not decode. Covers every float/double field of every
/// project type (a health check of recorded outputs: `livo-loginfo --nonfinite`).
int64_t countNonFinite(const void* data, int size);

/// The utime of an encoded project message whose first field is utime; false for other types.
bool messageUtime(const void* data, int size, int64_t* utime);
/// Rewrites that utime in place; false (and nothing changed) for other types.
bool setMessageUtime(void* data, int size, int64_t utime);

}  // namespace livo
