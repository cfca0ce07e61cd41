#include <gtest/gtest.h>

#include <limits>

#include "livo/playback/lockstep_gate.hpp"
#include "livo/playback/sender_clocks.hpp"

using livo::progress_t;
using livo::playback::LockstepGate;
using livo::playback::LockstepGateOptions;
using livo::playback::SenderClocks;

namespace {
progress_t progress(const std::string& node, int64_t seq, std::vector<std::pair<std::string, int64_t>> in,
                    std::vector<std::pair<std::string, int64_t>> out, bool finished = false, bool idle = false,
                    int64_t instance = 1) {
  progress_t p{};
  p.node = node;
  p.sequence = seq;
  p.finished = finished;
  p.idle = idle;
  p.instance = instance;
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

// The hang of issue 16: colour published a COLORED_CLOUD the recorder never got, while HEALTH kept
// flowing to the recorder. The stall is measured on the pair that is behind, not on any traffic.
TEST(LockstepGate, HeartbeatsDoNotHideAStall) {
  LockstepGate g({"colour", "record"});
  g.onProgress(progress("colour", 0, {{"REGISTERED_SCAN", 0}}, {{"COLORED_CLOUD", 0}, {"HEALTH", 0}}), 0.0);
  g.onProgress(progress("record", 0, {{"COLORED_CLOUD", 0}, {"HEALTH", 0}}, {}), 0.0);
  g.onPublished("REGISTERED_SCAN", 1.0);
  g.onProgress(progress("colour", 1, {{"REGISTERED_SCAN", 1}}, {{"COLORED_CLOUD", 1}, {"HEALTH", 0}}), 1.1);
  EXPECT_EQ(g.pendingDescription(), "record: COLORED_CLOUD 0/1");
  for (int k = 1; k <= 100; ++k) {  // a HEALTH a second from colour, each taken by the recorder
    const double t = 1.1 + k;
    g.onProgress(progress("colour", 1 + k, {{"REGISTERED_SCAN", 1}}, {{"COLORED_CLOUD", 1}, {"HEALTH", k}}), t);
    g.onProgress(progress("record", k, {{"COLORED_CLOUD", 0}, {"HEALTH", k}}, {}), t + 0.01);
  }
  EXPECT_FALSE(g.idle());
  EXPECT_NEAR(g.stalledFor(101.2), 100.1, 1e-9);  // since colour reported the cloud
  EXPECT_EQ(g.pendingDescription(), "record: COLORED_CLOUD 0/1");
  // a consumer that moves on the awaited channel resets its timer
  g.onProgress(progress("record", 101, {{"COLORED_CLOUD", 1}, {"HEALTH", 100}}, {}), 102.0);
  EXPECT_TRUE(g.idle());
  EXPECT_EQ(g.stalledFor(500.0), 0.0);
}

// An idle consumer (nothing in its receive queue) still lacking a message published more than the
// grace period ago never got it: counted as lost, reported once, and no longer waited for.
TEST(LockstepGate, AnIdleConsumerLackingAnOldMessageLostIt) {
  LockstepGateOptions o;
  o.loss_grace_s = 3.0;
  LockstepGate g({"lio", "record"}, o);
  g.onProgress(progress("lio", 0, {{"LIDAR", 0}}, {{"ODOMETRY", 0}}), 0.0);
  g.onProgress(progress("record", 0, {{"ODOMETRY", 0}}, {}), 0.0);
  g.onPublished("LIDAR", 10.0);
  g.onProgress(progress("lio", 1, {{"LIDAR", 1}}, {{"ODOMETRY", 2}}), 10.5);
  // busy (not idle) long after: not a loss, it may be working through its queue
  g.onProgress(progress("record", 1, {{"ODOMETRY", 1}}, {}, false, false), 20.0);
  EXPECT_EQ(g.lostMessages(), 0);
  // idle, but the message is younger than the grace period: not yet
  g.onProgress(progress("record", 2, {{"ODOMETRY", 1}}, {}, false, true), 12.0);
  EXPECT_EQ(g.lostMessages(), 0);
  EXPECT_FALSE(g.idle());
  // idle past the grace period: lost
  g.onProgress(progress("record", 3, {{"ODOMETRY", 1}}, {}, false, true), 13.6);
  EXPECT_EQ(g.lostMessages(), 1);
  EXPECT_EQ(g.lost().at("record: ODOMETRY"), 1);
  EXPECT_TRUE(g.idle());
  const auto events = g.takeEvents();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_NE(events[0].find("record never received 1 ODOMETRY message"), std::string::npos) << events[0];
  // the next message is waited for as usual, and a later idle report does not count the loss again
  g.onPublished("LIDAR", 20.0);
  g.onProgress(progress("lio", 2, {{"LIDAR", 2}}, {{"ODOMETRY", 3}}), 20.1);
  EXPECT_FALSE(g.idle());
  g.onProgress(progress("record", 4, {{"ODOMETRY", 2}}, {}, false, true), 30.0);
  EXPECT_TRUE(g.idle());
  EXPECT_EQ(g.lostMessages(), 1);
  EXPECT_TRUE(g.takeEvents().empty());
}

// Supervised runs: a consumer that exits is not waited for; when a new instance reports, what was
// published while it was away is lost to it and it is waited for again from there.
// The report that the CI machine once took for a loss: a heartbeat checked idle just before
// playback published, but received by a playback that was starved for longer than the grace
// period. It says nothing about the new message.
TEST(LockstepGate, AnIdleReportCheckedBeforeThePublishIsNotALoss) {
  LockstepGateOptions o;
  o.loss_grace_s = 1.0;
  LockstepGate g({"stage2"}, o);
  g.onProgress(progress("stage2", 0, {{"IMU", 0}}, {}, false, true), 0.0, 0.0);
  g.onPublished("IMU", 5.0);
  // checked at 4.99 s, handled by playback at 7 s: stale as to IMU #1
  g.onProgress(progress("stage2", 1, {{"IMU", 0}}, {}, false, true), 7.0, 4.99);
  EXPECT_EQ(g.lostMessages(), 0);
  EXPECT_FALSE(g.idle());
  // a clock that runs ahead of playback's receipt is not trusted beyond the receipt
  g.onProgress(progress("stage2", 2, {{"IMU", 0}}, {}, false, true), 5.5, 9.0);
  EXPECT_EQ(g.lostMessages(), 0);
  // checked idle 1.2 s after the publish: lost
  g.onProgress(progress("stage2", 3, {{"IMU", 0}}, {}, false, true), 7.1, 6.2);
  EXPECT_EQ(g.lostMessages(), 1);
  EXPECT_TRUE(g.idle());
}

// The same reports from a node on another host, whose clock reads 1000 s ahead of playback's
// (another boot): its check times, brought onto playback's clock by SenderClocks, decide as above.
// On playback's own host (offset 0) they come out at most the quickest delivery late.
TEST(LockstepGate, AnIdleReportFromAnotherHostIsJudgedOnPlaybacksClock) {
  for (const double offset : {1000.0, -1000.0, 0.0}) {
    LockstepGateOptions o;
    o.loss_grace_s = 1.0;
    LockstepGate g({"stage2"}, o);
    SenderClocks clocks;
    // (sequence, checked on playback's clock, received)
    auto report = [&](int64_t seq, double checked_s, double received_s) {
      const double local = clocks.toLocal("stage2", 1, checked_s + offset, received_s);
      EXPECT_GE(local, checked_s - 1e-9);
      EXPECT_LE(local, received_s + 1e-9);
      g.onProgress(progress("stage2", seq, {{"IMU", 0}}, {}, false, true), received_s, local);
      return local;
    };
    EXPECT_NEAR(report(0, 0.0, 0.002), 0.002, 1e-9);  // the first report: no better bound than its receipt
    g.onPublished("IMU", 5.0);
    EXPECT_NEAR(report(1, 4.99, 7.0), 4.992, 1e-9);  // received 2 s late: checked before the publish
    EXPECT_EQ(g.lostMessages(), 0);
    EXPECT_FALSE(g.idle());
    EXPECT_NEAR(report(2, 7.1, 7.1005), 7.1005, 1e-9);  // a quicker delivery tightens the bound
    EXPECT_EQ(g.lostMessages(), 1);                     // checked idle 2.1 s after the publish: lost
    EXPECT_TRUE(g.idle());
    EXPECT_NEAR(clocks.toLocal("stage2", 1, 8.0 + offset, 9.0), 8.0005, 1e-9);  // the bound stays
    // a new instance (restarted, maybe elsewhere) starts with no bound of its own
    EXPECT_NEAR(clocks.toLocal("stage2", 2, 500.0, 9.5), 9.5, 1e-9);
  }
}

TEST(LockstepGate, ToleratesRestartsWhenAsked) {
  LockstepGateOptions o;
  o.tolerate_restarts = true;
  o.silent_after_s = 5.0;
  LockstepGate g({"lio", "vio"}, o);
  g.onProgress(progress("lio", 0, {{"IMU", 0}}, {{"STATE_PRIOR", 0}}, false, false, 7), 0.0);
  g.onProgress(progress("vio", 0, {{"STATE_PRIOR", 0}}, {}, false, false, 8), 0.0);
  g.onPublished("IMU", 1.0);
  g.onProgress(progress("lio", 1, {{"IMU", 1}}, {{"STATE_PRIOR", 1}}, false, false, 7), 1.1);
  g.onProgress(progress("vio", 1, {{"STATE_PRIOR", 0}}, {}, true, false, 8), 1.2);  // SIGTERM: final PROGRESS
  EXPECT_TRUE(g.idle());                                                            // vio is away
  g.onPublished("IMU", 2.0);
  g.onProgress(progress("lio", 2, {{"IMU", 2}}, {{"STATE_PRIOR", 2}}, false, false, 7), 2.1);
  EXPECT_TRUE(g.idle());
  // a new vio: counts from zero; the two priors published before it came are not its due
  g.onProgress(progress("vio", 0, {{"STATE_PRIOR", 0}}, {}, false, false, 9), 3.0);
  EXPECT_EQ(g.restarts(), 1);
  EXPECT_TRUE(g.idle());
  EXPECT_TRUE(g.finished().empty());
  g.onPublished("IMU", 4.0);
  g.onProgress(progress("lio", 3, {{"IMU", 3}}, {{"STATE_PRIOR", 3}}, false, false, 7), 4.1);
  EXPECT_FALSE(g.idle());
  EXPECT_EQ(g.pendingDescription(), "vio: STATE_PRIOR 2/3");
  g.onProgress(progress("vio", 1, {{"STATE_PRIOR", 1}}, {}, false, false, 9), 4.2);
  EXPECT_TRUE(g.idle());
  // killed (no final PROGRESS): away once silent for silent_after_s
  g.onPublished("IMU", 5.0);
  g.onProgress(progress("lio", 4, {{"IMU", 4}}, {{"STATE_PRIOR", 4}}, false, false, 7), 5.1);
  g.checkSilent(8.0);
  EXPECT_FALSE(g.idle());
  g.checkSilent(9.3);
  EXPECT_TRUE(g.idle());
  const auto events = g.takeEvents();
  ASSERT_EQ(events.size(), 3u);
  EXPECT_NE(events[0].find("vio exited"), std::string::npos);
  EXPECT_NE(events[1].find("vio restarted; missed while it was away: 2 STATE_PRIOR"), std::string::npos) << events[1];
  EXPECT_NE(events[2].find("vio silent"), std::string::npos);
}

// Without tolerance a restart still rebases the counts (no wait for messages it cannot have).
TEST(LockstepGate, WithoutToleranceAnExitIsReported) {
  LockstepGate g({"a"});
  g.onProgress(progress("a", 0, {{"X", 0}}, {}), 0.0);
  g.onProgress(progress("a", 1, {{"X", 0}}, {}, true), 1.0);
  EXPECT_EQ(g.finished(), std::vector<std::string>{"a"});
  g.checkSilent(100.0);  // no effect without tolerate_restarts
  EXPECT_TRUE(g.takeEvents().empty());
}

TEST(LockstepGate, HoldsTheReplayWhileAConsumerRestarts) {
  LockstepGateOptions o;
  o.tolerate_restarts = true;
  o.restart_wait_s = 10.0;
  LockstepGate g({"vio"}, o);
  g.onProgress(progress("vio", 0, {{"CAMERA", 0}}, {}, false, false, 1), 0.0);
  EXPECT_FALSE(g.awaitingRestart(1.0));
  g.onProgress(progress("vio", 1, {{"CAMERA", 0}}, {}, true, false, 1), 2.0);
  EXPECT_TRUE(g.idle());
  EXPECT_TRUE(g.awaitingRestart(11.9));   // away since 2.0
  EXPECT_FALSE(g.awaitingRestart(12.1));  // given up waiting: the replay goes on without it
  g.onProgress(progress("vio", 0, {{"CAMERA", 0}}, {}, false, false, 2), 5.0);
  EXPECT_FALSE(g.awaitingRestart(5.0));
}

namespace {
progress_t withQuiet(progress_t p, const std::string& channel, int64_t from, int64_t before) {
  p.quiet_channel = {channel};
  p.quiet_from = {from};
  p.quiet_before = {before};
  p.num_quiet = 1;
  return p;
}
}  // namespace

// lio promises that IMU samples before its next sweep end publish nothing: playback sends them
// without waiting, and waits again for one past the promise or on another channel.
TEST(LockstepGate, AQuietPromiseLetsTheMessagesItCoversGoWithoutWaiting) {
  LockstepGate g({"lio"});
  g.onProgress(withQuiet(progress("lio", 0, {{"IMU", 0}, {"LIDAR", 0}}, {{"ODOMETRY", 0}}), "IMU", 0, 1000));
  g.onPublished("IMU", 0.0, 100);
  g.onPublished("IMU", 0.0, 999);
  EXPECT_TRUE(g.caughtUp());
  EXPECT_FALSE(g.idle());           // the end of the log still waits for everything
  g.onPublished("IMU", 0.0, 1000);  // at the promise's end: not covered
  EXPECT_FALSE(g.caughtUp());
  g.onProgress(withQuiet(progress("lio", 1, {{"IMU", 3}, {"LIDAR", 0}}, {{"ODOMETRY", 0}}), "IMU", 0, 1000));
  EXPECT_TRUE(g.caughtUp());
  g.onPublished("LIDAR", 0.0, 500);  // another channel: never covered
  EXPECT_FALSE(g.caughtUp());
  g.onProgress(progress("lio", 2, {{"IMU", 3}, {"LIDAR", 1}}, {{"ODOMETRY", 0}}));  // no promise now
  EXPECT_TRUE(g.caughtUp());
  g.onPublished("IMU", 0.0, 1001);
  EXPECT_FALSE(g.caughtUp());
  g.onProgress(withQuiet(progress("lio", 3, {{"IMU", 3}, {"LIDAR", 1}}, {{"ODOMETRY", 0}}), "IMU", 900, 2000));
  EXPECT_TRUE(g.caughtUp());
  g.onPublished("IMU", 0.0, 800);  // before the promise's start (a clock step back): not covered
  EXPECT_FALSE(g.caughtUp());
}

TEST(LockstepGate, APromiseCoversNeitherUnstampedMessagesNorChannelsNodesPublishNorASerialReplay) {
  LockstepGate g({"lio", "sim"});
  g.onProgress(withQuiet(progress("lio", 0, {{"IMU", 0}}, {}), "IMU", 0, 1000));
  g.onProgress(progress("sim", 0, {}, {{"IMU", 0}}));
  g.onPublished("IMU", 0.0, LockstepGate::kNoUtime);
  EXPECT_FALSE(g.caughtUp());
  g.onProgress(withQuiet(progress("lio", 1, {{"IMU", 1}}, {}), "IMU", 0, 1000));
  g.onPublished("IMU", 0.0, 10);
  EXPECT_TRUE(g.caughtUp());
  g.onProgress(progress("sim", 1, {}, {{"IMU", 1}}));  // a node publishes IMU too: its stamps are unknown
  EXPECT_FALSE(g.caughtUp());

  LockstepGateOptions serial;
  serial.honour_quiet_promises = false;
  LockstepGate s({"lio"}, serial);
  s.onProgress(withQuiet(progress("lio", 0, {{"IMU", 0}}, {}), "IMU", 0, 1000));
  s.onPublished("IMU", 0.0, 10);
  EXPECT_FALSE(s.caughtUp());
}

// colour and the recorder take what lio publishes but feed nothing back: they may fall a bounded
// number of messages behind while lio goes on.
TEST(LockstepGate, ALaggingConsumerFallsBehindByAtMostTheBound) {
  LockstepGateOptions o;
  o.may_lag = {"colour", "record"};
  o.max_lag_messages = 2;
  LockstepGate g({"lio", "colour", "record"}, o);
  g.onProgress(progress("lio", 0, {{"LIDAR", 0}}, {{"REGISTERED_SCAN", 0}}));
  g.onProgress(progress("colour", 0, {{"REGISTERED_SCAN", 0}, {"CAMERA", 0}}, {{"COLORED_CLOUD", 0}}));
  g.onProgress(progress("record", 0, {{"REGISTERED_SCAN", 0}, {"COLORED_CLOUD", 0}}, {}));
  EXPECT_EQ(g.lagging(), (std::vector<std::string>{"colour", "record"}));
  g.onPublished("LIDAR", 0.0, 1);
  EXPECT_FALSE(g.caughtUp());  // lio is in step
  g.onProgress(progress("lio", 1, {{"LIDAR", 1}}, {{"REGISTERED_SCAN", 1}}));
  EXPECT_TRUE(g.caughtUp());  // colour and record 1 behind
  g.onPublished("CAMERA", 0.0, 2);
  EXPECT_TRUE(g.caughtUp());  // colour 2 behind
  g.onPublished("CAMERA", 0.0, 3);
  EXPECT_FALSE(g.caughtUp());  // colour 3 behind
  EXPECT_FALSE(g.idle());
  g.onProgress(progress("colour", 1, {{"REGISTERED_SCAN", 1}, {"CAMERA", 0}}, {{"COLORED_CLOUD", 1}}));
  EXPECT_TRUE(g.caughtUp());  // colour 2 behind, the recorder 2 (a scan and a cloud)
  g.onProgress(progress("colour", 2, {{"REGISTERED_SCAN", 1}, {"CAMERA", 2}}, {{"COLORED_CLOUD", 1}}));
  g.onProgress(progress("record", 1, {{"REGISTERED_SCAN", 1}, {"COLORED_CLOUD", 1}}, {}));
  EXPECT_TRUE(g.idle());
}

// The backlog is bounded in bytes too, at each channel's mean message size (what nodes publish
// comes with their byte counts in PROGRESS): a receive buffer holds a few 64-beam clouds, not 16.
TEST(LockstepGate, ALaggingConsumerFallsBehindByAtMostTheByteBound) {
  LockstepGateOptions o;
  o.may_lag = {"colour"};
  o.max_lag_messages = 16;
  o.max_lag_bytes = 5'000'000;
  LockstepGate g({"lio", "colour"}, o);
  g.onProgress(progress("lio", 0, {{"LIDAR", 0}}, {{"REGISTERED_SCAN", 0}}));
  g.onProgress(progress("colour", 0, {{"REGISTERED_SCAN", 0}, {"CAMERA", 0}}, {{"COLORED_CLOUD", 0}}));
  ASSERT_EQ(g.lagging(), (std::vector<std::string>{"colour"}));
  g.onPublished("CAMERA", 0.0, 1, 900'000);
  g.onPublished("CAMERA", 0.0, 2, 900'000);
  EXPECT_TRUE(g.caughtUp());  // 1.8 MB behind
  g.onPublished("LIDAR", 0.0, 3, 2'000'000);
  progress_t lio = progress("lio", 1, {{"LIDAR", 1}}, {{"REGISTERED_SCAN", 1}});
  lio.published_bytes = {3'000'000};
  g.onProgress(lio);
  EXPECT_TRUE(g.caughtUp());  // 4.8 MB behind (two images and lio's scan), 3 messages
  g.onPublished("CAMERA", 0.0, 4, 900'000);
  EXPECT_FALSE(g.caughtUp());  // 5.7 MB behind, 4 messages
  g.onProgress(progress("colour", 1, {{"REGISTERED_SCAN", 0}, {"CAMERA", 2}}, {{"COLORED_CLOUD", 0}}));
  EXPECT_TRUE(g.caughtUp());  // 3.9 MB behind
}

// octomap takes colour's clouds: colour lagging would hand them to octomap at positions that
// depend on timing, so it is kept in step (and says so); the recorder taking them does not count.
TEST(LockstepGate, AConsumerWhoseOutputAnotherActsOnIsKeptInStep) {
  LockstepGateOptions o;
  o.may_lag = {"colour", "octomap", "record"};
  LockstepGate g({"lio", "colour", "octomap", "record"}, o);
  g.onProgress(progress("lio", 0, {{"LIDAR", 0}}, {{"REGISTERED_SCAN", 0}}));
  g.onProgress(progress("colour", 0, {{"REGISTERED_SCAN", 0}}, {{"COLORED_CLOUD", 0}}));
  g.onProgress(progress("record", 0, {{"REGISTERED_SCAN", 0}, {"COLORED_CLOUD", 0}, {"OCTOMAP", 0}}, {}));
  EXPECT_EQ(g.lagging(), (std::vector<std::string>{"colour", "record"}));  // octomap not heard yet
  g.onProgress(progress("octomap", 0, {{"REGISTERED_SCAN", 0}, {"COLORED_CLOUD", 0}}, {{"OCTOMAP", 0}}));
  EXPECT_EQ(g.lagging(), (std::vector<std::string>{"octomap", "record"}));
  const auto events = g.takeEvents();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0], "consumer colour kept in step (it may not lag): octomap takes its COLORED_CLOUD");
  g.onPublished("LIDAR", 0.0, 1);
  g.onProgress(progress("lio", 1, {{"LIDAR", 1}}, {{"REGISTERED_SCAN", 1}}));
  EXPECT_FALSE(g.caughtUp());  // colour must take the scan before the next message
  g.onProgress(progress("colour", 1, {{"REGISTERED_SCAN", 1}}, {{"COLORED_CLOUD", 1}}));
  EXPECT_TRUE(g.caughtUp());  // octomap and the recorder behind, within the bound
}

// vio promises every REGISTERED_SCAN (it only adds it to its map): lio's scans need no stamps to be
// covered, but the backlog a whole-channel promise lets build up is bounded.
TEST(LockstepGate, AWholeChannelPromiseCoversWhatNodesPublishUpToABacklog) {
  LockstepGate g({"lio", "vio"});
  g.onProgress(progress("lio", 0, {{"LIDAR", 0}}, {{"REGISTERED_SCAN", 0}}));
  progress_t vio = progress("vio", 0, {{"REGISTERED_SCAN", 0}}, {{"STATE_POSTERIOR", 0}});
  vio.quiet_channel = {"REGISTERED_SCAN"};
  vio.quiet_from = {std::numeric_limits<int64_t>::min()};
  vio.quiet_before = {std::numeric_limits<int64_t>::max()};
  vio.num_quiet = 1;
  g.onProgress(vio);
  for (int k = 1; k <= 8; ++k) {
    g.onPublished("LIDAR", 0.0, k);
    g.onProgress(progress("lio", k, {{"LIDAR", k}}, {{"REGISTERED_SCAN", k}}));
    EXPECT_TRUE(g.caughtUp()) << k << " scans behind";
  }
  g.onPublished("LIDAR", 0.0, 9);
  g.onProgress(progress("lio", 9, {{"LIDAR", 9}}, {{"REGISTERED_SCAN", 9}}));
  EXPECT_FALSE(g.caughtUp());  // 9 behind
  EXPECT_FALSE(g.idle());
}

namespace {
constexpr int64_t kAny = std::numeric_limits<int64_t>::min(), kEver = std::numeric_limits<int64_t>::max();
/// lio waiting for a posterior: IMU before `imu_before` and STATE_POSTERIOR (any) promised quiet.
progress_t lioWaiting(int64_t seq, int64_t imu, int64_t posteriors, int64_t priors, bool posterior_quiet = true,
                      int64_t imu_before = 1000) {
  progress_t p = progress("lio", seq, {{"IMU", imu}, {"STATE_POSTERIOR", posteriors}}, {{"STATE_PRIOR", priors}});
  p.quiet_channel = {"IMU"};
  p.quiet_from = {0};
  p.quiet_before = {imu_before};
  if (posterior_quiet) {
    p.quiet_channel.push_back("STATE_POSTERIOR");
    p.quiet_from.push_back(kAny);
    p.quiet_before.push_back(kEver);
  }
  p.num_quiet = static_cast<int32_t>(p.quiet_channel.size());
  return p;
}
}  // namespace

// An answer in flight: while vio works on a prior, playback may send what vio does not take and
// what is quiet for everyone else, as long as vio's answer reaches only a consumer that promised it
// quiet (lio, waiting for it) and recorders. Anything else waits for vio, as caughtUp() always does.
TEST(LockstepGate, AnAnswerInFlightLetsOnlyQuietMessagesForOthersGo) {
  LockstepGateOptions o;
  o.may_lag = {"record"};
  LockstepGate g({"lio", "vio", "record"}, o);
  g.onProgress(lioWaiting(0, 0, 0, 0));
  g.onProgress(progress("vio", 0, {{"CAMERA", 0}, {"STATE_PRIOR", 0}}, {{"STATE_POSTERIOR", 0}}));
  g.onProgress(progress("record", 0, {{"STATE_POSTERIOR", 0}, {"IMU", 0}}, {}));
  ASSERT_EQ(g.lagging(), std::vector<std::string>{"record"});
  g.onPublished("IMU", 0.0, 100);
  g.onProgress(lioWaiting(1, 1, 0, 1));     // lio handed an image off: vio owes an answer
  EXPECT_FALSE(g.caughtUp());               // (the rule that does not know the next message)
  EXPECT_TRUE(g.mayPublish("IMU", 500));    // quiet for lio, not vio's
  EXPECT_FALSE(g.mayPublish("IMU", 1000));  // lio would act on it: wait for the answer
  EXPECT_FALSE(g.mayPublish("IMU", LockstepGate::kNoUtime));
  EXPECT_FALSE(g.mayPublish("CAMERA", 500));       // vio takes it
  EXPECT_TRUE(g.mayPublish("GROUND_TRUTH", 500));  // nobody in step takes it
  g.onPublished("IMU", 0.0, 500);
  EXPECT_TRUE(g.mayPublish("IMU", 600));                            // lio has not handled the last one: still quiet
  g.onProgress(lioWaiting(2, 2, 0, 1, /*posterior_quiet=*/false));  // it would act on the answer now
  EXPECT_FALSE(g.mayPublish("IMU", 600));

  // the answer comes: lio owes its handling; quiet messages go, one lio would act on waits for it
  // (the answer and the message come from different senders, in no fixed order)
  g.onProgress(lioWaiting(3, 2, 0, 1));
  g.onProgress(progress("vio", 1, {{"CAMERA", 0}, {"STATE_PRIOR", 1}}, {{"STATE_POSTERIOR", 1}}));
  EXPECT_TRUE(g.caughtUp());
  EXPECT_TRUE(g.mayPublish("IMU", 600));
  EXPECT_TRUE(g.mayPublish("CAMERA", 600));
  EXPECT_FALSE(g.mayPublish("IMU", 1000));
  g.onProgress(lioWaiting(4, 2, 1, 1, false));
  EXPECT_TRUE(g.mayPublish("IMU", 1000));
}

TEST(LockstepGate, AnAnswerIsNotInFlightWithLaggingOrBusyTakersNorInASerialReplay) {
  auto start = [](LockstepGate& g, bool colour_takes_posterior) {
    g.onProgress(lioWaiting(0, 0, 0, 0));
    g.onProgress(progress("vio", 0, {{"CAMERA", 0}, {"STATE_PRIOR", 0}}, {{"STATE_POSTERIOR", 0}}));
    if (colour_takes_posterior)  // even promising it quiet: a promise about a state it may be far behind
      g.onProgress(withQuiet(progress("colour", 0, {{"STATE_POSTERIOR", 0}, {"CAMERA", 0}}, {{"COLORED_CLOUD", 0}}),
                             "STATE_POSTERIOR", kAny, kEver));
    g.onPublished("IMU", 0.0, 100);
    g.onProgress(lioWaiting(1, 1, 0, 1));
  };
  {  // a lagging consumer that takes the answer would see it among playback's messages by timing
    LockstepGateOptions o;
    o.may_lag = {"colour"};
    LockstepGate g({"lio", "vio", "colour"}, o);
    start(g, true);
    ASSERT_EQ(g.lagging(), std::vector<std::string>{"colour"});
    EXPECT_FALSE(g.mayPublish("IMU", 500));
  }
  {  // a serial replay honours no promise
    LockstepGateOptions o;
    o.honour_quiet_promises = false;
    LockstepGate g({"lio", "vio"}, o);
    start(g, false);
    EXPECT_FALSE(g.mayPublish("IMU", 500));
  }
  {  // lio itself busy with something it did not promise quiet (a loop correction)
    LockstepGate g({"lio", "vio", "loop"});
    g.onProgress(progress("loop", 0, {}, {{"LOOP_CORRECTION", 0}}));
    start(g, false);
    EXPECT_TRUE(g.mayPublish("IMU", 500));
    progress_t p = lioWaiting(2, 1, 0, 1);
    p.input_channel.push_back("LOOP_CORRECTION");
    p.handled.push_back(0);
    p.num_inputs = static_cast<int32_t>(p.input_channel.size());
    g.onProgress(p);
    g.onProgress(progress("loop", 1, {}, {{"LOOP_CORRECTION", 1}}));
    EXPECT_FALSE(g.mayPublish("IMU", 500));
  }
}
