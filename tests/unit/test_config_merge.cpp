// livo-config's merge (processes/config): overlays over a base, the header naming the files, and
// the refusals a process would give.
#include <gtest/gtest.h>

#include <fstream>

#include "livo/config.hpp"
#include "livo/config/merged_config.hpp"
#include "livo/config_overlays.hpp"
#include "temp_path.hpp"

using namespace livo;
using namespace livo::config;

namespace {
std::string write(const std::string& name, const std::string& text) {
  const std::string path = livo_test::tempPath(name);
  std::ofstream(path) << text;
  return path;
}
}  // namespace

TEST(ConfigMerge, MergesOverlaysInOrderUnderAHeaderNamingTheFiles) {
  const std::string base = write("base.yaml", "lio: {init: {window_s: 0.5}, point_stride: 2}\nvio: {}\n");
  const std::string a = write("a.yaml", "lio: {point_stride: 3}\n");
  const std::string b = write("b.yaml", "lio: {point_stride: 4, init: {window_s: 1.0}}\n");
  const std::string text = mergedConfig(base, {a, b});
  EXPECT_EQ(text.rfind("# livo-config merge: " + base + " + " + a + " + " + b + "\n", 0), 0u) << text;
  const Config merged = Config::fromString(text.substr(text.find('\n') + 1));
  int stride = 0;
  double window = 0.0;
  merged.section("lio").readOptional("point_stride", stride);
  merged.section("lio").section("init").readOptional("window_s", window);
  EXPECT_EQ(stride, 4);  // the last overlay wins
  EXPECT_DOUBLE_EQ(window, 1.0);
  EXPECT_EQ(mergedConfig(base, {}).rfind("# livo-config merge: " + base + "\n", 0), 0u);
}

TEST(ConfigMerge, RefusesAnUnknownSectionAndAMissingFile) {
  const std::string base = write("base2.yaml", "lio: {}\n");
  const std::string typo = write("typo.yaml", "loi: {point_stride: 3}\n");
  EXPECT_THROW(mergedConfig(base, {typo}), ConfigError);
  EXPECT_THROW(mergedConfig(base, {livo_test::tempPath("absent.yaml")}), ConfigError);
}

TEST(ConfigMerge, SplitsTheOverlayList) {
  EXPECT_EQ(overlayFiles("a.yaml,,b.yaml"), (std::vector<std::string>{"a.yaml", "b.yaml"}));
  EXPECT_TRUE(overlayFiles("").empty());
}
