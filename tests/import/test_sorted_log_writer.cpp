// The writer's output is in time order with stable ties, in memory and through spilled runs.
#include <gtest/gtest.h>

#include "livo/import/sorted_log_writer.hpp"
#include "livo/imu_t.hpp"
#include "log_reading.hpp"

namespace livo::import {
namespace {

void writeShuffled(SortedLogWriter& w) {
  // Stamps 0..99 in a scrambled order; every stamp appears on two channels (a tie) in a known order.
  for (int i = 0; i < 100; ++i) {
    const int t = (i * 37) % 100;
    imu_t m{};
    m.utime = t;
    m.angular_velocity[0] = i;  // insertion index
    w.add("A", m);
    w.add("B", m);
  }
}

void expectSortedStable(const std::string& path) {
  const auto events = test::readLog(path);
  ASSERT_EQ(events.size(), 200u);
  for (size_t k = 0; k < events.size(); ++k) {
    EXPECT_EQ(events[k].timestamp, static_cast<int64_t>(k / 2));
    EXPECT_EQ(events[k].channel, k % 2 == 0 ? "A" : "B") << "ties keep insertion order";
  }
}

TEST(SortedLogWriter, SortsInMemory) {
  const std::string dir = test::freshTempDir("writer_memory");
  SortedLogWriter w(dir + "/out.lcmlog");
  writeShuffled(w);
  w.finish();
  EXPECT_EQ(w.runFiles(), 0);
  EXPECT_EQ(w.counts().at("A"), 100);
  expectSortedStable(dir + "/out.lcmlog");
}

TEST(SortedLogWriter, SortsThroughSpilledRuns) {
  const std::string dir = test::freshTempDir("writer_spill");
  SortedLogWriterOptions o;
  o.max_buffer_bytes = 2000;  // a run every few dozen messages
  SortedLogWriter w(dir + "/out.lcmlog", o);
  writeShuffled(w);
  EXPECT_GT(w.runFiles(), 3);
  w.finish();
  expectSortedStable(dir + "/out.lcmlog");
  EXPECT_EQ(std::system(("test -z \"$(ls " + dir + " | grep tmp)\"").c_str()), 0) << "run files removed";
}

}  // namespace
}  // namespace livo::import
