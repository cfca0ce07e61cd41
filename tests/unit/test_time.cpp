#include <gtest/gtest.h>

#include "livo/time.hpp"

using livo::TimeBuffer;

TEST(Time, Conversions) {
  EXPECT_EQ(livo::toUtime(1.5), 1500000);
  EXPECT_EQ(livo::toUtime(1e-6 * 3 + 1e-12), 3);
  EXPECT_DOUBLE_EQ(livo::toSeconds(2500000), 2.5);
}

TEST(TimeBuffer, OrdersOutOfOrderArrivalsAndRefusesConsumedTimes) {
  TimeBuffer<int> b;
  EXPECT_TRUE(b.insert(30, 3));
  EXPECT_TRUE(b.insert(10, 1));
  EXPECT_TRUE(b.insert(20, 2));
  EXPECT_TRUE(b.insert(20, 22));  // equal stamps keep arrival order
  std::vector<int> got;
  b.popUntil(20, [&](const TimeBuffer<int>::Entry& e) { got.push_back(e.value); });
  EXPECT_EQ(got, (std::vector<int>{1, 2, 22}));
  EXPECT_FALSE(b.insert(15, 9));  // behind the watermark
  EXPECT_FALSE(b.insert(20, 9));
  EXPECT_TRUE(b.insert(25, 4));
  got.clear();
  b.popUntil(100, [&](const TimeBuffer<int>::Entry& e) { got.push_back(e.value); });
  EXPECT_EQ(got, (std::vector<int>{4, 3}));
  EXPECT_TRUE(b.empty());
}

TEST(TimeBuffer, Bracket) {
  std::vector<int64_t> t = {0, 10, 20, 40};
  size_t i;
  double a;
  auto id = [](int64_t x) { return x; };
  ASSERT_TRUE(livo::bracket(t, 30, id, &i, &a));
  EXPECT_EQ(i, 2u);
  EXPECT_DOUBLE_EQ(a, 0.5);
  ASSERT_TRUE(livo::bracket(t, 0, id, &i, &a));
  EXPECT_EQ(i, 0u);
  EXPECT_DOUBLE_EQ(a, 0.0);
  ASSERT_TRUE(livo::bracket(t, 40, id, &i, &a));
  EXPECT_EQ(i, 2u);
  EXPECT_DOUBLE_EQ(a, 1.0);
  EXPECT_FALSE(livo::bracket(t, 41, id, &i, &a));
  EXPECT_FALSE(livo::bracket(t, -1, id, &i, &a));
}
