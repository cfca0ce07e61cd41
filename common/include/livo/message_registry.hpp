// Every LCM type of the project, looked up by the fingerprint that starts each encoded message.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace livo {

struct MessageType {
  std::string name;      // package-qualified, e.g. "livo.point_cloud_t"
  int64_t fingerprint;   // the 8 bytes every encoded message starts with
};

/// All project types.
const std::vector<MessageType>& messageTypes();

/// The type whose fingerprint starts `data`, or nullptr.
const MessageType* identifyMessage(const void* data, int size);

}  // namespace livo
