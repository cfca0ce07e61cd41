#include "livo/file_output.hpp"

#include <filesystem>
#include <fstream>

namespace livo {

bool writeFileAtomically(const std::string& path, const std::function<bool(std::ostream&)>& write, std::string* error) {
  auto fail = [&](const std::string& what) {
    if (error) *error = what;
    return false;
  };
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return fail("cannot write " + tmp);
    const bool ok = write(out);
    out.flush();
    if (!ok || !out) return fail("write failed: " + tmp);
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) return fail("cannot rename " + tmp + " to " + path + ": " + ec.message());
  return true;
}

bool writeFileAtomically(const std::string& path, std::initializer_list<std::string_view> parts, std::string* error) {
  return writeFileAtomically(
      path,
      [&](std::ostream& out) {
        for (std::string_view part : parts) out.write(part.data(), static_cast<std::streamsize>(part.size()));
        return true;
      },
      error);
}

}  // namespace livo
