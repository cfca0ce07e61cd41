// The node framework on the in-process memq:// provider: decoding, failures, PROGRESS, HEALTH.
#include <gtest/gtest.h>

#include "livo/health_t.hpp"
#include "livo/imu_t.hpp"
#include "livo/node.hpp"
#include "livo/progress_t.hpp"

using namespace livo;

namespace {
void drain(lcm::LCM& lcm) {
  while (lcm.handleTimeout(0) > 0) {
  }
}
}  // namespace

TEST(Node, DecodesCountsFailuresAndReportsProgress) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  NodeOptions opts;
  opts.name = "test_node";
  opts.quiet = true;
  Node node(lcm, opts);
  node.declareOutput("ECHO");

  std::vector<int64_t> seen;
  node.subscribe<imu_t>("IMU", [&](const imu_t& m) {
    if (m.utime < 0) throw std::runtime_error("negative time");
    seen.push_back(m.utime);
    imu_t echo = m;
    node.publish("ECHO", echo);
  });

  std::vector<progress_t> progress;
  std::vector<health_t> health;
  Node observer(lcm, NodeOptions{"observer", "PROGRESS_OBS", "HEALTH_OBS", 0.0, false, true, {}});
  observer.subscribe<progress_t>("PROGRESS", [&](const progress_t& p) { progress.push_back(p); });
  observer.subscribe<health_t>("HEALTH", [&](const health_t& h) { health.push_back(h); });

  imu_t m{};
  m.utime = 100;
  lcm.publish("IMU", &m);
  m.utime = 200;
  lcm.publish("IMU", &m);
  const uint8_t junk[5] = {9, 9, 9, 9, 9};
  lcm.publish("IMU", junk, sizeof(junk));  // does not decode
  m.utime = -5;
  lcm.publish("IMU", &m);  // handler throws: rejected, not fatal
  drain(lcm);

  EXPECT_EQ(seen, (std::vector<int64_t>{100, 200}));
  EXPECT_EQ(node.handled("IMU"), 4);
  EXPECT_EQ(node.decodeFailures(), 1);
  EXPECT_EQ(node.published("ECHO"), 2);
  const auto stats = node.channelStats();
  ASSERT_EQ(stats.size(), 1u);
  EXPECT_EQ(stats[0].messages, 4);
  EXPECT_EQ(stats[0].decode_failures, 1);
  EXPECT_EQ(stats[0].rejected, 1);
  EXPECT_GE(stats[0].max_ms, 0.0);

  // one PROGRESS per handled message, counts increasing
  ASSERT_EQ(progress.size(), 4u);
  for (size_t i = 0; i < progress.size(); ++i) {
    EXPECT_EQ(progress[i].node, "test_node");
    EXPECT_EQ(progress[i].sequence, static_cast<int64_t>(i));
    ASSERT_EQ(progress[i].num_inputs, 1);
    EXPECT_EQ(progress[i].input_channel[0], "IMU");
    EXPECT_EQ(progress[i].handled[0], static_cast<int64_t>(i + 1));
    ASSERT_EQ(progress[i].num_outputs, 1);
    EXPECT_EQ(progress[i].output_channel[0], "ECHO");
  }
  EXPECT_EQ(progress.back().published[0], 2);
  ASSERT_EQ(progress.back().published_bytes.size(), 1u);  // the echoes' encoded bytes
  EXPECT_EQ(progress.back().published_bytes[0], 2 * imu_t{}.getEncodedSize());

  node.finish();
  node.finish();  // idempotent
  drain(lcm);
  ASSERT_EQ(progress.size(), 5u);
  EXPECT_EQ(progress.back().finished, 1);
  ASSERT_EQ(health.size(), 1u);
  EXPECT_EQ(health[0].node, "test_node");
  EXPECT_EQ(health[0].level, int8_t{health_t::LEVEL_WARN});
  ASSERT_EQ(health[0].num_channels, 1);
  EXPECT_EQ(health[0].channels[0].decode_failures, 1);
  EXPECT_GT(health[0].peak_rss_mb, 0.0);
}

TEST(Node, SpinStopsWhenDone) {
  lcm::LCM lcm("memq://");
  NodeOptions opts;
  opts.name = "spinner";
  opts.quiet = true;
  Node node(lcm, opts);
  int n = 0;
  node.subscribe<imu_t>("IMU", [&](const imu_t&) { ++n; });
  imu_t m{};
  for (int i = 0; i < 3; ++i) lcm.publish("IMU", &m);
  bool flushed = false;
  EXPECT_EQ(spin(
                lcm, node, [&] { flushed = true; }, [&] { return n == 3; }),
            0);
  EXPECT_EQ(n, 3);
  EXPECT_TRUE(flushed);
}

TEST(Node, RejectsEmptyName) {
  lcm::LCM lcm("memq://");
  EXPECT_THROW(Node(lcm, NodeOptions{}), std::invalid_argument);
}

// watchConsumers: a node learns from the others' PROGRESS whether anyone subscribes to a channel;
// its own subscriptions do not count, a finished node stops counting, watching adds no input.
TEST(Node, WatchesConsumersOfAChannel) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  Node producer(lcm, NodeOptions{"producer", "PROGRESS", "HEALTH", 0.0, true, true, {}});
  producer.subscribe<imu_t>("STATE_PRIOR", [](const imu_t&) {});  // its own subscription
  producer.watchConsumers("STATE_PRIOR");
  producer.watchConsumers("OTHER");
  producer.announce();
  drain(lcm);
  EXPECT_FALSE(producer.hasConsumers("STATE_PRIOR"));
  EXPECT_FALSE(producer.hasConsumers("UNWATCHED"));
  {
    Node consumer(lcm, NodeOptions{"consumer", "PROGRESS", "HEALTH", 0.0, true, true, {}});
    consumer.subscribe<imu_t>("STATE_PRIOR", [](const imu_t&) {});
    consumer.announce();
    drain(lcm);
    EXPECT_TRUE(producer.hasConsumers("STATE_PRIOR"));
    EXPECT_FALSE(producer.hasConsumers("OTHER"));
    consumer.finish();
    drain(lcm);
    EXPECT_FALSE(producer.hasConsumers("STATE_PRIOR"));
  }
  // watching is not an input: the producer's PROGRESS lists only its own subscription
  std::vector<std::string> inputs;
  Node listener(lcm, NodeOptions{"listener", "PROGRESS_L", "HEALTH_L", 0.0, false, true, {}});
  listener.subscribe<progress_t>("PROGRESS", [&](const progress_t& p) {
    if (p.node == "producer") inputs = p.input_channel;
  });
  producer.announce();
  drain(lcm);
  EXPECT_EQ(inputs, std::vector<std::string>{"STATE_PRIOR"});
}
