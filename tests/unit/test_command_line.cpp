#include <gtest/gtest.h>

#include <sstream>

#include "livo/command_line.hpp"
#include "livo/config_check.hpp"

namespace {
struct Argv {
  std::vector<std::string> s;
  std::vector<char*> p;
  explicit Argv(std::vector<std::string> a) : s(std::move(a)) {
    for (auto& x : s) p.push_back(&x[0]);
  }
  int argc() { return static_cast<int>(p.size()); }
  char** argv() { return p.data(); }
};
livo::CommandLine make() {
  livo::CommandLine c("prog", "test");
  c.positional("LOG", "log")
      .option("--speed", "X", "speed", "1.0")
      .option("--out", "F", "out")
      .flag("--lockstep", "ls");
  return c;
}
}  // namespace

TEST(CommandLine, ParsesOptionsFlagsAndPositionals) {
  auto c = make();
  Argv a({"prog", "x.lcmlog", "--speed", "2.5", "--lockstep", "--out=o.log"});
  ASSERT_TRUE(c.parse(a.argc(), a.argv()));
  EXPECT_EQ(c.get("LOG"), "x.lcmlog");
  EXPECT_DOUBLE_EQ(c.getDouble("--speed"), 2.5);
  EXPECT_TRUE(c.has("--lockstep"));
  EXPECT_EQ(c.get("--out"), "o.log");
}

TEST(CommandLine, DefaultsAndErrors) {
  {
    auto c = make();
    Argv a({"prog", "x"});
    ASSERT_TRUE(c.parse(a.argc(), a.argv()));
    EXPECT_DOUBLE_EQ(c.getDouble("--speed"), 1.0);
    EXPECT_FALSE(c.has("--lockstep"));
    EXPECT_FALSE(c.has("--out"));
  }
  {
    auto c = make();
    Argv a({"prog", "x", "--sped", "2"});
    EXPECT_FALSE(c.parse(a.argc(), a.argv()));
    EXPECT_EQ(c.exitCode(), 2);
  }
  {
    auto c = make();
    Argv a({"prog"});
    EXPECT_FALSE(c.parse(a.argc(), a.argv()));
    EXPECT_EQ(c.exitCode(), 2);
  }
  {
    auto c = make();
    Argv a({"prog", "x", "--speed"});
    EXPECT_FALSE(c.parse(a.argc(), a.argv()));
  }
  {
    auto c = make();
    Argv a({"prog", "x", "--speed", "fast"});
    ASSERT_TRUE(c.parse(a.argc(), a.argv()));
    EXPECT_THROW(c.getDouble("--speed"), std::invalid_argument);
  }
}

// --check-config (every process that reads a config): declared once, answered once the options
// are read; without it the process goes on to start.
TEST(CommandLine, ConfigCheckFlag) {
  auto command = [] {
    livo::CommandLine c("livo-x", "test");
    c.option("--config", "FILE", "config");
    livo::declareConfigCheck(c);
    return c;
  };
  {
    auto c = command();
    Argv a({"livo-x", "--config", "rig.yaml", "--check-config"});
    ASSERT_TRUE(c.parse(a.argc(), a.argv()));
    std::ostringstream out;
    EXPECT_TRUE(livo::configCheckDone(c, out));
    EXPECT_EQ(out.str(), "livo-x: rig.yaml: valid (--check-config: not started)\n");
    EXPECT_NE(c.usage().find("--check-config"), std::string::npos);
  }
  {
    auto c = command();
    Argv a({"livo-x", "--config", "rig.yaml"});
    ASSERT_TRUE(c.parse(a.argc(), a.argv()));
    std::ostringstream out;
    EXPECT_FALSE(livo::configCheckDone(c, out));
    EXPECT_EQ(out.str(), "");
  }
}
