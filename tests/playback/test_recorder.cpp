// livo-record's stamps: each event carries its message's own utime; events before the first one
// (a node's HEALTH before any sensor time says 0) are held and written with it, so a recorded log
// never starts at time 0 and jumps by decades (it did: an outputs log "lasted" 1.7e9 s and its
// replay's progress line said so).
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "bus_messages.hpp"
#include "livo/health_t.hpp"
#include "livo/node.hpp"
#include "livo/odometry_t.hpp"
#include "livo/record/recorder.hpp"
#include "temp_path.hpp"

namespace livo::record {
namespace {

using livo_test::drain;

struct Event {
  int64_t timestamp;
  std::string channel;
  int64_t message_utime;
};

std::vector<Event> readBack(const std::string& path) {
  lcm::LogFile log(path, "r");
  EXPECT_TRUE(log.good());
  std::vector<Event> events;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    health_t h;
    odometry_t o;
    int64_t utime = -1;
    if (e->channel == "HEALTH" && h.decode(e->data, 0, e->datalen) > 0) utime = h.utime;
    if (e->channel == "ODOMETRY" && o.decode(e->data, 0, e->datalen) > 0) utime = o.utime;
    events.push_back({e->timestamp, e->channel, utime});
  }
  return events;
}

TEST(Recorder, EventsBeforeTheFirstStampTakeItAndNoneGoesBackToZero) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  NodeOptions opts;
  opts.name = "record";
  opts.health_period_s = 0.0;
  opts.publish_progress = false;
  opts.quiet = true;
  Node node(lcm, opts);
  const std::string path = livo_test::tempPath("recorded.lcmlog");
  {
    Recorder recorder(node, path, {"HEALTH", "ODOMETRY"});
    health_t early{};
    early.utime = 0;  // a node that has seen no sensor time yet
    early.node = "lio";
    lcm.publish("HEALTH", &early);
    const uint8_t junk[5] = {9, 9, 9, 9, 9};  // no type of ours, no stamp: held as well
    lcm.publish("HEALTH", junk, sizeof(junk));
    drain(lcm);
    EXPECT_EQ(recorder.written(), 0);  // held until a stamp comes
    odometry_t odo{};
    odo.utime = 1700000000500000;
    lcm.publish("ODOMETRY", &odo);
    drain(lcm);
    health_t idle{};
    idle.utime = 0;  // a node that still has none, later in the run
    idle.node = "octomap";
    lcm.publish("HEALTH", &idle);
    odo.utime = -3;  // a malformed stamp does not move the log's clock either
    lcm.publish("ODOMETRY", &odo);
    odo.utime = 1700000000600000;
    lcm.publish("ODOMETRY", &odo);
    drain(lcm);
    recorder.finish();
    EXPECT_EQ(recorder.written(), 6);
  }
  const std::vector<Event> events = readBack(path);
  ASSERT_EQ(events.size(), 7u);  // the six, then the recorder's own final HEALTH
  EXPECT_EQ(events[0].channel, "HEALTH");
  EXPECT_EQ(events[0].message_utime, 0);
  EXPECT_EQ(events[0].timestamp, 1700000000500000);  // held, then written with the first stamp
  EXPECT_EQ(events[1].message_utime, -1);            // the junk, kept as it came
  EXPECT_EQ(events[1].timestamp, 1700000000500000);
  EXPECT_EQ(events[2].timestamp, 1700000000500000);
  EXPECT_EQ(events[3].channel, "HEALTH");
  EXPECT_EQ(events[3].timestamp, 1700000000500000);  // the last stamp, not 0
  EXPECT_EQ(events[4].message_utime, -3);
  EXPECT_EQ(events[4].timestamp, 1700000000500000);  // nor a negative one
  EXPECT_EQ(events[5].timestamp, 1700000000600000);
  for (size_t i = 1; i < events.size(); ++i) EXPECT_GE(events[i].timestamp, events[i - 1].timestamp) << i;
}

}  // namespace
}  // namespace livo::record
