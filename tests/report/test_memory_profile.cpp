// livo-report memory: the peak RSS per node at checkpoints of sensor time.
#include <cmath>

#include <gtest/gtest.h>

#include "livo/report/memory_profile.hpp"

using livo::report::MemoryProfile;

TEST(MemoryProfile, PeakAtCheckpointsAndTheRunsEnd) {
  MemoryProfile p;
  p.first_seconds = 100.0;
  p.last_seconds = 399.4;  // the last HEALTH 0.6 s before a 300 s log ends
  p.samples["colour"] = {{0.5, 10.0}, {60.0, 20.0}, {150.0, 30.0}, {299.4, 40.0}};
  p.samples["lio"] = {{1.0, 5.0}, {299.0, 5.5}};
  EXPECT_TRUE(std::isnan(p.peakAt("colour", 0.1)));  // nothing reported yet
  EXPECT_DOUBLE_EQ(p.peakAt("colour", 60.0), 20.0);
  EXPECT_DOUBLE_EQ(p.peakAt("colour", 149.9), 20.0);
  EXPECT_DOUBLE_EQ(p.peakAt("colour", 300.0), 40.0);   // the checkpoint at the log's end counts
  EXPECT_TRUE(std::isnan(p.peakAt("colour", 900.0)));  // beyond the run
  EXPECT_TRUE(std::isnan(p.peakAt("vio", 60.0)));      // no such node
  const std::string table = livo::report::memoryTable(p, {60.0, 300.0, 900.0});
  EXPECT_NE(table.find("| colour | 20.0 | 40.0 | - | - | 40.0 |"), std::string::npos) << table;
  EXPECT_NE(table.find("| lio | 5.0 | 5.5 | - | - | 5.5 |"), std::string::npos) << table;
}
