// The team of the step's loops (core/thread_team.hpp): every loop runs its body once on every thread of the team,
// forked or held; a held loop returns only when every thread has finished it and what they wrote is visible;
// OpenMP barriers and worksharing inside a held body bind to the held team; a driver's exception leaves the hold
// with the team released; a hold inside a hold is the outer one; a hold reads the cores once; and ThreadMax is the
// maximum of what the threads put. That a run's bits do not depend on the team is checked by
// tests/determinism_test.cpp and tests/fused_run_test.cpp, whose runs hold their teams.
#include <gtest/gtest.h>

#include <omp.h>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "core/thread_team.hpp"

using namespace fl;

namespace {
// per-thread counts of the body's calls, each on a line of its own
struct alignas(64) Count {
  long calls = 0;
  int teamSize = 0;
  int ompThread = -1;
};
}  // namespace

TEST(ThreadTeam, OneThreadIsAPlainCall) {
  ThreadTeam team;
  int calls = 0, seenT = -1, seenNt = -1;
  const auto body = [&](int t, int nt) {
    ++calls;
    seenT = t;
    seenNt = nt;
    EXPECT_FALSE(omp_in_parallel());
  };
  team.each(1, body);
  team.hold(1, [&] { team.each(1, body); });
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(seenT, 0);
  EXPECT_EQ(seenNt, 1);
  EXPECT_EQ(team.held(), 0);
}

TEST(ThreadTeam, ForkedLoopRunsOnEveryThreadOnce) {
  ThreadTeam team;
  std::vector<Count> counts(3);
  const auto body = [&](int t, int nt) {
    ++counts[static_cast<std::size_t>(t)].calls;
    counts[static_cast<std::size_t>(t)].teamSize = nt;
    counts[static_cast<std::size_t>(t)].ompThread = omp_get_thread_num();
  };
  team.each(3, body);
  const int nt = counts[0].teamSize;
  ASSERT_GE(nt, 1);
  for (int t = 0; t < nt; ++t) {
    EXPECT_EQ(counts[static_cast<std::size_t>(t)].calls, 1) << "thread " << t;
    EXPECT_EQ(counts[static_cast<std::size_t>(t)].teamSize, nt);
    EXPECT_EQ(counts[static_cast<std::size_t>(t)].ompThread, t);
  }
}

TEST(ThreadTeam, HeldLoopsRunOnEveryThreadAndEndTogether) {
  // Each loop adds to every thread's own count; right after each(), thread 0 reads all counts: a loop that
  // returned before another thread had finished (or before its writes were visible) would show a count behind.
  for (const int threads : {2, 3, 4}) {
    ThreadTeam team;
    std::vector<Count> counts(static_cast<std::size_t>(threads));
    std::vector<long> shared(4096, 0);
    constexpr long kLoops = 2000;
    int held = 0;
    long behind = 0, wrongShared = 0;
    team.hold(threads, [&] {
      held = team.held();
      for (long k = 1; k <= kLoops; ++k) {
        const auto body = [&](int t, int nt) {
          Count& c = counts[static_cast<std::size_t>(t)];
          ++c.calls;
          c.teamSize = nt;
          c.ompThread = omp_get_thread_num();
          // each thread writes its static share of a shared array (the loop's data, not only its count)
          const std::size_t n = shared.size(), b = n * static_cast<std::size_t>(t) / static_cast<std::size_t>(nt),
                            e = n * static_cast<std::size_t>(t + 1) / static_cast<std::size_t>(nt);
          for (std::size_t i = b; i < e; ++i) shared[i] = k;
        };
        team.each(threads, body);
        for (int t = 0; t < held; ++t) behind += counts[static_cast<std::size_t>(t)].calls != k;
        for (const long v : shared) wrongShared += v != k;
      }
    });
    EXPECT_EQ(team.held(), 0);
    ASSERT_GE(held, 2) << "OpenMP gave no second thread";
    EXPECT_EQ(behind, 0) << threads << " threads";
    EXPECT_EQ(wrongShared, 0) << threads << " threads";
    for (int t = 0; t < held; ++t) {
      EXPECT_EQ(counts[static_cast<std::size_t>(t)].calls, kLoops);
      EXPECT_EQ(counts[static_cast<std::size_t>(t)].teamSize, held);
      EXPECT_EQ(counts[static_cast<std::size_t>(t)].ompThread, t);
    }
  }
}

TEST(ThreadTeam, OpenMpBarrierAndWorksharingBindToTheHeldTeam) {
  ThreadTeam team;
  constexpr int kItems = 1000;
  std::vector<int> claimed(kItems, 0);
  std::vector<Count> afterBarrier(2);
  std::atomic<int> arrived{0};
  team.hold(2, [&] {
    const auto body = [&](int t, int) {
#pragma omp for schedule(dynamic, 7)
      for (int i = 0; i < kItems; ++i) ++claimed[static_cast<std::size_t>(i)];  // each item by one thread
      arrived.fetch_add(1);
#pragma omp barrier
      afterBarrier[static_cast<std::size_t>(t)].calls = arrived.load();  // every thread arrived before
    };
    team.each(2, body);
  });
  for (int i = 0; i < kItems; ++i) EXPECT_EQ(claimed[static_cast<std::size_t>(i)], 1) << "item " << i;
  EXPECT_EQ(afterBarrier[0].calls, 2);
  EXPECT_EQ(afterBarrier[1].calls, 2);
}

TEST(ThreadTeam, DriverExceptionLeavesTheHoldWithTheTeamReleased) {
  ThreadTeam team;
  long loops = 0;
  EXPECT_THROW(team.hold(2,
                         [&] {
                           const auto body = [&](int t, int) {
                             if (t == 0) ++loops;
                           };
                           team.each(2, body);
                           throw std::runtime_error("stop");
                         }),
               std::runtime_error);
  EXPECT_EQ(loops, 1);
  EXPECT_EQ(team.held(), 0);
  // the team serves a new hold, and forks outside one
  std::vector<Count> counts(2);
  team.hold(2, [&] {
    const auto body = [&](int t, int) { ++counts[static_cast<std::size_t>(t)].calls; };
    for (int k = 0; k < 10; ++k) team.each(2, body);
  });
  EXPECT_EQ(counts[0].calls, 10);
  EXPECT_EQ(counts[1].calls, 10);
  const auto body = [&](int t, int) { ++counts[static_cast<std::size_t>(t)].calls; };
  team.each(2, body);
  EXPECT_EQ(counts[0].calls, 11);
  EXPECT_EQ(counts[1].calls, 11);
}

TEST(ThreadTeam, HoldInsideAHoldIsTheOuterOne) {
  ThreadTeam team;
  int innerHeld = -1;
  std::vector<Count> counts(2);
  team.hold(2, [&] {
    team.hold(2, [&] {
      innerHeld = team.held();
      const auto body = [&](int t, int) { ++counts[static_cast<std::size_t>(t)].calls; };
      team.each(2, body);
    });
    EXPECT_EQ(team.held(), innerHeld);  // still held after the inner hold
  });
  EXPECT_EQ(innerHeld, 2);
  EXPECT_EQ(counts[0].calls, 1);
  EXPECT_EQ(counts[1].calls, 1);
  EXPECT_EQ(team.held(), 0);
}

// The cores the pass's waits count with: read once when a hold begins (the step asks for them every pass, and
// omp_get_num_procs is a system call when the threads are not bound), and the same as outside it.
TEST(ThreadTeam, CoresAreTheProcessorsAvailableInsideAndOutsideAHold) {
  ThreadTeam team;
  const int procs = omp_get_num_procs();
  EXPECT_EQ(team.cores(), procs);
  int inside = -1;
  team.hold(2, [&] { inside = team.cores(); });
  EXPECT_EQ(inside, procs);
  EXPECT_EQ(team.held(), 0);
  EXPECT_EQ(team.cores(), procs);
}

TEST(ThreadTeam, ThreadMaxIsTheLargestPut) {
  ThreadMax m;
  m.reset(3);
  EXPECT_EQ(m.max(), 0.0);  // nothing put: a displacement of zero
  m.put(0, 1.5);
  m.put(2, 4.25);
  m.put(1, 2.0);
  EXPECT_EQ(m.max(), 4.25);
  m.reset(2);  // a new loop starts from zero
  EXPECT_EQ(m.max(), 0.0);
  ThreadTeam team;
  m.reset(2);
  team.hold(2, [&] {
    const auto body = [&](int t, int) { m.put(t, 10.0 + t); };
    team.each(2, body);
  });
  EXPECT_EQ(m.max(), 11.0);
}
