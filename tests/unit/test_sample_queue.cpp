// SampleQueue: samples taken only in time order (a stale one refused, not reordered), handed over
// oldest first while ready, and the last stamp taken kept as the stream's watermark.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "livo/sample_queue.hpp"

using livo::SampleQueue;

TEST(SampleQueue, RefusesASampleNotLaterThanTheNewestHeld) {
  SampleQueue<std::string> q;
  EXPECT_EQ(q.watermark(), INT64_MIN);
  EXPECT_TRUE(q.takes(5));
  EXPECT_TRUE(q.pushLater(10, "a"));
  EXPECT_FALSE(q.takes(10));
  EXPECT_FALSE(q.pushLater(10, "duplicate"));
  EXPECT_FALSE(q.pushLater(7, "older"));
  EXPECT_TRUE(q.pushLater(11, "b"));
  EXPECT_EQ(q.size(), 2u);
  EXPECT_EQ(q.front(), "a");
  EXPECT_EQ(q.back(), "b");
  EXPECT_EQ(q.watermark(), 11);
}

TEST(SampleQueue, HandsOverTheOldestWhileReady) {
  SampleQueue<int> q;
  for (int t : {1, 2, 3, 4}) q.pushLater(t, t);
  std::vector<int> seen;
  q.popWhile([](int t) { return t <= 2; }, [&](int t) { seen.push_back(t); });
  EXPECT_EQ(seen, (std::vector<int>{1, 2}));
  EXPECT_EQ(q.front(), 3);
  q.popFront();
  EXPECT_EQ(q.samples().size(), 1u);
  EXPECT_EQ(q.samples().front(), 4);
}

TEST(SampleQueue, OnceEmptyTakesAnyStampAndTheWatermarkFollowsIt) {
  SampleQueue<int> q;
  q.pushLater(20, 20);
  q.popFront();
  EXPECT_TRUE(q.empty());
  EXPECT_EQ(q.watermark(), 20);      // the stream got to 20, though nothing is held
  EXPECT_TRUE(q.pushLater(15, 15));  // only the samples held order the next one
  EXPECT_EQ(q.watermark(), 15);
}
