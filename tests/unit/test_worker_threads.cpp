#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "livo/worker_threads.hpp"

using livo::WorkerThreads;

TEST(WorkerThreads, EveryIndexIsHandledExactlyOnceInContiguousShares) {
  for (int threads : {1, 2, 3, 4}) {
    WorkerThreads team(threads);
    EXPECT_EQ(team.threads(), threads);
    for (size_t n : {0, 1, 5, 255, 256, 1000, 1001}) {
      for (size_t min_share : {1, 100}) {
        std::vector<int> count(n, 0);
        std::mutex m;
        std::vector<std::pair<size_t, size_t>> shares;
        team.forEachShare(
            n,
            [&](size_t b, size_t e) {
              for (size_t i = b; i < e; ++i) ++count[i];  // each index belongs to one share
              std::lock_guard<std::mutex> lock(m);
              shares.emplace_back(b, e);
            },
            min_share);
        for (size_t i = 0; i < n; ++i)
          ASSERT_EQ(count[i], 1) << "index " << i << " of " << n << ", " << threads << " threads";
        const size_t expected = std::max<size_t>(1, std::min<size_t>(threads, n / min_share));
        EXPECT_EQ(shares.size(), expected) << n << " indices, " << threads << " threads, min_share " << min_share;
        if (shares.size() > 1) {
          for (const auto& [b, e] : shares) EXPECT_GE(e - b, min_share);
        }
      }
    }
  }
}

TEST(WorkerThreads, SharesRunOnTheHelperThreadsAtOnce) {
  WorkerThreads team(3);
  std::mutex m;
  std::set<std::thread::id> ids;
  std::atomic<int> inside{0};
  int most_inside = 0;
  team.forEachShare(3, [&](size_t, size_t) {
    const int now = ++inside;
    {
      std::lock_guard<std::mutex> lock(m);
      ids.insert(std::this_thread::get_id());
      most_inside = std::max(most_inside, now);
    }
    // wait (bounded) until all three shares are inside: they run at once, not one after another
    for (int i = 0; i < 2000 && inside.load() < 3; ++i) std::this_thread::sleep_for(std::chrono::microseconds(500));
    std::lock_guard<std::mutex> lock(m);
    most_inside = std::max(most_inside, inside.load());
  });
  EXPECT_EQ(ids.size(), 3u);
  EXPECT_TRUE(ids.count(std::this_thread::get_id()));  // the caller takes a share
  EXPECT_EQ(most_inside, 3);
}

TEST(WorkerThreads, AnExceptionInAnyShareReachesTheCallerAndTheTeamGoesOn) {
  WorkerThreads team(2);
  for (size_t failing : {size_t{0}, size_t{7}}) {  // the caller's share, then the helper's
    EXPECT_THROW(team.forEachShare(10,
                                   [&](size_t b, size_t e) {
                                     if (b <= failing && failing < e) throw std::runtime_error("share failed");
                                   }),
                 std::runtime_error);
  }
  std::atomic<size_t> sum{0};
  team.forEachShare(100, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) sum += i;
  });
  EXPECT_EQ(sum.load(), 4950u);
  EXPECT_THROW(WorkerThreads(0), std::invalid_argument);
}
