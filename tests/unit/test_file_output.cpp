#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "livo/file_output.hpp"
#include "temp_path.hpp"

using namespace livo;

namespace {
std::string contents(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}
}  // namespace

TEST(FileOutput, WritesThePartsInOrderAndReplacesTheFile) {
  const std::string path = livo_test::tempPath("atomic.bin");
  std::string error;
  ASSERT_TRUE(writeFileAtomically(path, {"header\n", std::string_view("a\0b", 3)}, &error)) << error;
  EXPECT_EQ(contents(path), std::string("header\na\0b", 10));
  ASSERT_TRUE(writeFileAtomically(path, {"new"}, &error)) << error;
  EXPECT_EQ(contents(path), "new");
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  EXPECT_FALSE(writeFileAtomically(livo_test::tempPath("no/such/folder/x.bin"), {"x"}, &error));
  EXPECT_NE(error.find("cannot write"), std::string::npos) << error;
}
