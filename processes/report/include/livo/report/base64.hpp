// Base64 (RFC 4648, with padding): how report.html carries its pictures and the map's points.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace livo::report {

std::string base64Encode(const void* data, size_t size);
inline std::string base64Encode(std::string_view bytes) { return base64Encode(bytes.data(), bytes.size()); }

}  // namespace livo::report
