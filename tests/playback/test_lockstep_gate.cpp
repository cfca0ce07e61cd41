#include <gtest/gtest.h>

#include "lockstep_gate.hpp"

using livo::LockstepGate;
using livo::progress_t;

namespace {
progress_t progress(const std::string& node, int64_t seq, std::vector<std::pair<std::string, int64_t>> in,
                    std::vector<std::pair<std::string, int64_t>> out, bool finished = false) {
  progress_t p{};
  p.node = node;
  p.sequence = seq;
  p.finished = finished;
  for (auto& [c, n] : in) p.input_channel.push_back(c), p.handled.push_back(n);
  for (auto& [c, n] : out) p.output_channel.push_back(c), p.published.push_back(n);
  p.num_inputs = static_cast<int32_t>(p.input_channel.size());
  p.num_outputs = static_cast<int32_t>(p.output_channel.size());
  return p;
}
}  // namespace

TEST(LockstepGate, WaitsForTheWholeChain) {
  LockstepGate g({"lio", "vio"});
  EXPECT_FALSE(g.allPresent());
  g.onProgress(progress("lio", 0, {{"IMU", 0}, {"LIDAR", 0}, {"STATE_POSTERIOR", 0}}, {{"STATE_PRIOR", 0}}));
  EXPECT_EQ(g.missing(), std::vector<std::string>{"vio"});
  g.onProgress(progress("vio", 0, {{"CAMERA", 0}, {"STATE_PRIOR", 0}}, {{"STATE_POSTERIOR", 0}}));
  EXPECT_TRUE(g.allPresent());
  EXPECT_TRUE(g.idle());

  g.onPublished("CAMERA");  // vio must take it
  EXPECT_FALSE(g.idle());
  EXPECT_EQ(g.pendingDescription(), "vio: CAMERA 0/1");
  g.onPublished("IMU");
  EXPECT_FALSE(g.idle());
  // lio takes IMU and publishes a prior; vio has not seen it yet
  g.onProgress(progress("lio", 1, {{"IMU", 1}, {"LIDAR", 0}, {"STATE_POSTERIOR", 0}}, {{"STATE_PRIOR", 1}}));
  g.onProgress(progress("vio", 1, {{"CAMERA", 1}, {"STATE_PRIOR", 0}}, {{"STATE_POSTERIOR", 0}}));
  EXPECT_FALSE(g.idle());
  EXPECT_EQ(g.pendingDescription(), "vio: STATE_PRIOR 0/1");
  g.onProgress(progress("vio", 2, {{"CAMERA", 1}, {"STATE_PRIOR", 1}}, {{"STATE_POSTERIOR", 1}}));
  EXPECT_FALSE(g.idle());  // lio has not taken the posterior yet
  EXPECT_EQ(g.pendingDescription(), "lio: STATE_POSTERIOR 0/1");
  g.onProgress(progress("lio", 2, {{"IMU", 1}, {"LIDAR", 0}, {"STATE_POSTERIOR", 1}}, {{"STATE_PRIOR", 1}}));
  EXPECT_TRUE(g.idle());
}

TEST(LockstepGate, IgnoresStaleProgressAndReportsFinished) {
  LockstepGate g({"a"});
  EXPECT_TRUE(g.onProgress(progress("a", 5, {{"X", 3}}, {})));
  EXPECT_FALSE(g.onProgress(progress("a", 4, {{"X", 2}}, {})));  // late datagram: ignored
  EXPECT_FALSE(g.onProgress(progress("a", 6, {{"X", 3}}, {})));  // heartbeat: nothing moved
  g.onPublished("X");
  g.onPublished("X");
  g.onPublished("X");
  EXPECT_TRUE(g.idle());
  EXPECT_TRUE(g.finished().empty());
  EXPECT_TRUE(g.onProgress(progress("a", 7, {{"X", 3}}, {}, true)));
  EXPECT_EQ(g.finished(), std::vector<std::string>{"a"});
  // nodes outside the consumer list publish, but are not waited for
  g.onProgress(progress("logger", 0, {{"Y", 0}}, {{"X", 1}}));
  EXPECT_FALSE(g.idle());
}
