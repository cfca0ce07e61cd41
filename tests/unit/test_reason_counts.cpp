// ReasonCounts: reasons grouped by their text before " (", the summary a node's final HEALTH
// carries, and reading it back.
#include <gtest/gtest.h>

#include "livo/reason_counts.hpp"

using livo::parseReasonCounts;
using livo::ReasonCounts;

TEST(ReasonCounts, GroupsReasonsByTheirTextBeforeTheNumbers) {
  ReasonCounts r;
  r.add("too few patches (12)");
  r.add("too few patches (9)");
  r.add("no image at the prior's time (a newer image came)");
  r.add("bad image; too dark", 3);  // ';' separates the summary's items
  EXPECT_EQ(r.total(), 6);
  EXPECT_EQ(r.counts().at("too few patches"), 2);
  EXPECT_EQ(r.counts().at("bad image, too dark"), 3);
  EXPECT_EQ(r.summary("priors kept"),
            "priors kept by reason: 3 x bad image, too dark; 2 x too few patches; 1 x no image at the prior's time");
  EXPECT_EQ(ReasonCounts().summary("priors kept"), "");
}

TEST(ReasonCounts, SummaryReadsBack) {
  ReasonCounts r;
  r.add("before the visual state was initialised (waiting for the IMU at rest)", 40);
  r.add("image not later than the previous one");
  const auto parsed = parseReasonCounts(r.summary("images refused"));
  ASSERT_TRUE(parsed.has_value());
  EXPECT_EQ(parsed->what, "images refused");
  EXPECT_EQ(parsed->reasons.counts(), r.counts());
}

TEST(ReasonCounts, OtherTextIsNotASummary) {
  for (const char* text :
       {"", "odometry reset to epoch 1: IMU gap", "priors kept by reason: ", "priors kept by reason: many x too few",
        "priors kept by reason: 3 too few", "priors kept by reason: -2 x too few", " by reason: 2 x too few"})
    EXPECT_FALSE(parseReasonCounts(text).has_value()) << text;
}
