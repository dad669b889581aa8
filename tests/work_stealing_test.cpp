// The claims of the step's parallel loops (core/work_stealing.hpp): every item is taken exactly once, an owner
// takes its own share from the front in runs of the grain, a thread whose own share is empty takes the share
// before its own from the back, and a team of another size gets the static split; a reader of a round's
// progress (RoundProgress) finds the items it waited for. That the bits do not depend
// on who computed which item is checked by tests/determinism_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <random>
#include <thread>
#include <vector>

#include "core/work_stealing.hpp"

using namespace fl;

namespace {
struct ItemRun {
  std::size_t begin, end;
};

std::vector<ItemRun> drain(StealingRanges& r, int t, int nt, std::size_t count) {
  std::vector<ItemRun> runs;
  ThreadRuns claims(r, t, nt, count);
  for (std::size_t b, e; claims.next(b, e);) runs.push_back({b, e});
  return runs;
}

// the static shares of `count` items among nt threads, as StealingRanges::reset takes them
std::vector<std::size_t> staticBounds(int nt, std::size_t count) {
  std::vector<std::size_t> bounds(static_cast<std::size_t>(nt) + 1);
  for (int t = 0; t <= nt; ++t) bounds[static_cast<std::size_t>(t)] = staticBegin(t, nt, count);
  return bounds;
}

// thread t's next run is [b, e)
void expectRun(StealingRanges& r, int t, std::size_t b, std::size_t e) {
  std::size_t begin = 0, end = 0;
  ASSERT_TRUE(r.next(t, begin, end));
  EXPECT_EQ(begin, b);
  EXPECT_EQ(end, e);
}
}  // namespace

TEST(WorkStealing, StaticBeginSplitsLikeScheduleStatic) {
  EXPECT_EQ(staticBegin(0, 3, 10), 0u);
  EXPECT_EQ(staticBegin(1, 3, 10), 4u);  // the first 10 % 3 shares are one longer
  EXPECT_EQ(staticBegin(2, 3, 10), 7u);
  EXPECT_EQ(staticBegin(3, 3, 10), 10u);
  EXPECT_EQ(staticBegin(1, 4, 2), 1u);
  EXPECT_EQ(staticBegin(3, 4, 2), 2u);
}

TEST(WorkStealing, OwnerTakesItsShareFromTheFrontInRunsOfTheGrain) {
  StealingRanges r;
  r.reset({0, 10, 25}, 4);
  expectRun(r, 1, 10, 14);
  expectRun(r, 1, 14, 18);
  expectRun(r, 1, 18, 22);
  expectRun(r, 1, 22, 25);  // the last run is what is left
  expectRun(r, 1, 6, 10);   // share 1 is empty: thread 1 now takes share 0 from its back
  expectRun(r, 0, 0, 4);    // thread 0 still has [0, 6) at its front
  expectRun(r, 1, 4, 6);
  std::size_t b = 0, e = 0;
  EXPECT_FALSE(r.next(0, b, e));
  EXPECT_FALSE(r.next(1, b, e));
  EXPECT_EQ(r.stolen(), 2u);
}

TEST(WorkStealing, ThreadZeroStealsFromTheLastShare) {
  StealingRanges r;
  r.reset({0, 3, 6, 9}, 2);
  std::size_t b = 0, e = 0;
  while (r.next(0, b, e) && b < 3) {
  }
  EXPECT_EQ(b, 7u);  // share 2 from its back: [7, 9) first
  EXPECT_EQ(e, 9u);
}

TEST(WorkStealing, ATeamOfAnotherSizeGetsTheStaticSplitWhole) {
  StealingRanges r;
  r.reset({0, 50, 100}, 8);
  const std::vector<ItemRun> runs = drain(r, 1, 3, 100);  // 3 threads, ranges for 2
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].begin, 34u);
  EXPECT_EQ(runs[0].end, 67u);
  StealingRanges one;
  one.reset({0, 100}, 8);
  const std::vector<ItemRun> whole = drain(one, 0, 1, 100);  // one thread: its share in one run, no claims
  ASSERT_EQ(whole.size(), 1u);
  EXPECT_EQ(whole[0].end - whole[0].begin, 100u);
}

// A thread that starts late finds its share taken: the other thread did all of it, from the back, in runs of
// the grain, and every item was taken once.
TEST(WorkStealing, ALateThreadFindsItsShareDoneByTheOther) {
  StealingRanges r;
  r.reset({0, 40, 100}, 3);
  std::vector<ItemRun> first, second;
  std::atomic<bool> done{false};
  std::thread late([&] {
    while (!done.load()) std::this_thread::yield();
    second = drain(r, 1, 2, 100);
  });
  first = drain(r, 0, 2, 100);
  done = true;
  late.join();
  EXPECT_TRUE(second.empty());
  std::vector<int> taken(100, 0);
  std::size_t previousBegin = 101;
  for (const ItemRun& run : first) {
    EXPECT_LE(run.end - run.begin, 3u);
    for (std::size_t i = run.begin; i < run.end; ++i) ++taken[i];
    if (run.begin >= 40) {  // stolen runs come from the back, one below the other
      EXPECT_LT(run.begin, previousBegin);
      previousBegin = run.begin;
    }
  }
  for (int c : taken) EXPECT_EQ(c, 1);
}

// Four threads with random pauses, many loops: each item exactly once per loop, and some runs stolen.
TEST(WorkStealing, EveryItemIsTakenOnceUnderContention) {
  constexpr int kThreads = 4;
  constexpr std::size_t kItems = 1000;
  StealingRanges r;
  const std::vector<std::size_t> bounds = staticBounds(kThreads, kItems);
  long stolen = 0;
  for (int loop = 0; loop < 50; ++loop) {
    r.reset(bounds, 1 + static_cast<std::size_t>(loop % 7));
    std::vector<std::atomic<int>> taken(kItems);
    std::vector<long> stolenBy(kThreads, 0);
    std::vector<std::thread> team;
    for (int t = 0; t < kThreads; ++t)
      team.emplace_back([&, t] {
        std::mt19937 rng(static_cast<unsigned>(loop * kThreads + t));
        ThreadRuns claims(r, t, kThreads, kItems);
        for (std::size_t b, e; claims.next(b, e);) {
          if (rng() % 4 == 0) std::this_thread::sleep_for(std::chrono::microseconds(rng() % 50));
          for (std::size_t i = b; i < e; ++i) taken[i].fetch_add(1);
          stolenBy[t] += b < bounds[t] || b >= bounds[t + 1];
        }
      });
    for (std::thread& th : team) th.join();
    for (std::size_t i = 0; i < kItems; ++i) ASSERT_EQ(taken[i].load(), 1) << "loop " << loop << ", item " << i;
    for (long s : stolenBy) stolen += s;
  }
  EXPECT_GT(stolen, 0) << "the random pauses should have left some runs to be stolen";
}

// The two-phase claims (nextOwn, then nextTaken with doneTaken) of the contact pass, which sums its seeds from
// its whole share between them: once waitForTakers returns, every item of the owner's share has been written,
// by the owner or by the thread that took it. Thieves are slowed at random, and
// write their items with plain stores, so a wait that returned early would read a zero (and TSan, in the
// sanitizer pass, would report the race). Checked by hand: without the wait, the owners read unwritten items.
TEST(WorkStealing, AnOwnerWaitsForTheRunsTakenFromItsShare) {
  constexpr int kThreads = 3;
  constexpr std::size_t kItems = 600;
  StealingRanges r;
  const std::vector<std::size_t> bounds = staticBounds(kThreads, kItems);
  long takenRuns = 0;
  for (int loop = 0; loop < 40; ++loop) {
    r.reset(bounds, 1 + static_cast<std::size_t>(loop % 5));
    std::vector<int> value(kItems, 0);
    std::vector<long> seen(kThreads, 0), taken(kThreads, 0);
    std::vector<std::thread> team;
    for (int t = 0; t < kThreads; ++t)
      team.emplace_back([&, t] {
        std::mt19937 rng(static_cast<unsigned>(loop * kThreads + t));
        ThreadRuns claims(r, t, kThreads, kItems);
        std::size_t b = 0, e = 0;
        while (claims.nextOwn(b, e)) {
          // the owner of share 0 is slow, so the others finish first and take its runs
          if (t == 0) std::this_thread::sleep_for(std::chrono::microseconds(20 + rng() % 40));
          for (std::size_t i = b; i < e; ++i) value[i] = 1;
        }
        claims.waitForTakers();
        for (std::size_t i = bounds[t]; i < bounds[t + 1]; ++i) seen[t] += value[i];
        while (claims.nextTaken(b, e)) {
          std::this_thread::sleep_for(std::chrono::microseconds(rng() % 60));
          for (std::size_t i = b; i < e; ++i) value[i] = 1;
          claims.doneTaken(e - b);
          ++taken[t];
        }
      });
    for (std::thread& th : team) th.join();
    for (int t = 0; t < kThreads; ++t)
      EXPECT_EQ(seen[t], static_cast<long>(bounds[t + 1] - bounds[t])) << "loop " << loop << ", share " << t;
    for (long k : taken) takenRuns += k;
  }
  EXPECT_GT(takenRuns, 0) << "the slow owner should have had runs taken";
}

// One thread, or a team of another size: nextOwn gives the static share whole, nothing is taken, nobody waits.
TEST(WorkStealing, TwoPhaseClaimsOfAStaticShare) {
  StealingRanges r;
  r.reset({0, 5, 10}, 2);
  ThreadRuns claims(r, 1, 3, 9);  // a team of 3 against ranges for 2: static
  std::size_t b = 0, e = 0;
  ASSERT_TRUE(claims.nextOwn(b, e));
  EXPECT_EQ(b, 3u);
  EXPECT_EQ(e, 6u);
  EXPECT_FALSE(claims.nextOwn(b, e));
  claims.waitForTakers();
  EXPECT_FALSE(claims.nextTaken(b, e));
}

// A round's progress (RoundProgress, the contact pass's halo): two owners write their items in batches of random
// size at random speed and publish each count; a reader that asks for the first k items of an owner finds all
// k written in this round, and is told at least k. Rounds follow one another as the passes do (the team meets
// between them). With a no-op wait the reader finds items of the last round. Once with as many threads as
// cores, once as if on one core (the waits then yield almost at once), and once with the rounds restarting
// every 4 (as after 2^32 passes), where a value is tagged with the pass, not the round.
TEST(WorkStealing, AReaderFindsTheItemsAnOwnerPublishedInThisRound) {
  constexpr int kThreads = 3;  // thread 0 reads, 1 and 2 own items
  constexpr std::uint32_t kItems = 300;
  struct Case {
    int cores;
    std::uint64_t restartAt;
  };
  for (const Case c : {Case{kThreads, std::uint64_t{1} << 32}, Case{1, std::uint64_t{1} << 32}, Case{kThreads, 5}}) {
    SCOPED_TRACE(c.cores);
    SCOPED_TRACE(c.restartAt);
    RoundProgress progress(c.restartAt);
    std::vector<std::vector<long>> value(kThreads, std::vector<long>(kItems, 0));
    std::atomic<long> stale{0}, short_{0}, checked{0};
    std::uint64_t restarts = 0, last = 0;
    for (int pass = 1; pass <= 30; ++pass) {
      const std::uint64_t round = progress.beginRound(kThreads, c.cores);
      ASSERT_GE(round, 1u);
      ASSERT_LT(round, c.restartAt);
      restarts += round <= last;
      last = round;
      std::vector<std::thread> team;
      for (int t = 0; t < kThreads; ++t)
        team.emplace_back([&, t] {
          std::mt19937 rng(static_cast<unsigned>(pass * kThreads + t));
          if (t > 0) {
            std::uint32_t done = 0;
            while (done < kItems) {
              const std::uint32_t end = std::min(kItems, done + 1 + static_cast<std::uint32_t>(rng() % 40));
              if (rng() % 2) std::this_thread::sleep_for(std::chrono::microseconds(rng() % 30));
              for (; done < end; ++done) value[t][done] = pass;
              progress.publish(t, round, done);
            }
            return;
          }
          for (std::uint32_t need = 0; need < kItems;) {
            need = std::min(kItems, need + 1 + static_cast<std::uint32_t>(rng() % 25));
            for (int s = 1; s < kThreads; ++s) {
              const std::uint32_t have = progress.waitFor(s, round, need);
              short_ += have < need;
              for (std::uint32_t i = 0; i < need; ++i) stale += value[s][i] != pass;
              checked += need;
            }
          }
        });
      for (std::thread& th : team) th.join();
    }
    EXPECT_EQ(stale.load(), 0) << "items read before their owner wrote them in this round";
    EXPECT_EQ(short_.load(), 0);
    EXPECT_GT(checked.load(), 0);
    EXPECT_EQ(restarts, c.restartAt == 5 ? 7u : 0u);  // rounds 1-4, then again from 1: 30 passes restart 7 times
  }
}
