// A private temporary folder per test process: ctest runs the tests of one executable as
// parallel processes, so fixed names under /tmp would collide. Removed when the process ends.
#pragma once

#include <unistd.h>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace livo_test {

inline const std::string& tempDir() {
  struct Dir {
    std::string path;
    Dir() : path(::testing::TempDir() + "livo-test-" + std::to_string(::getpid())) {
      std::filesystem::create_directories(path);
    }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

/// tempDir() + "/" + name.
inline std::string tempPath(const std::string& name) { return tempDir() + "/" + name; }

}  // namespace livo_test
