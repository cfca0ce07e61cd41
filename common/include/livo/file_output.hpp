// Writing output files so that a reader (a viewer, the next run of a script) never sees a half-
// written one: the bytes go to PATH.tmp, which is then renamed over PATH.
#pragma once

#include <functional>
#include <initializer_list>
#include <iosfwd>
#include <string>
#include <string_view>

namespace livo {

/// Writes the parts, in order, as the new contents of `path`; false with `error` (if given) when
/// the file cannot be written or renamed (PATH.tmp may then be left behind).
bool writeFileAtomically(const std::string& path, std::initializer_list<std::string_view> parts,
                         std::string* error = nullptr);
/// The same with the contents streamed by `write` (false from it: the write failed), for files
/// too large to hold in memory.
bool writeFileAtomically(const std::string& path, const std::function<bool(std::ostream&)>& write,
                         std::string* error = nullptr);

}  // namespace livo
