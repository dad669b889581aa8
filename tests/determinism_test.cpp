// Deterministic parallelism (house style §12): the same scene gives the same bits with 1 to 8 threads, whichever
// thread computed what.
#include <gtest/gtest.h>

#include "core/simulation.hpp"
#include "test_support.hpp"

using namespace fl;

using test::compressingGas;
using test::expectSameBits;

TEST(Determinism, OneAndTwoThreadsGiveIdenticalBits) {
  Simulation a = compressingGas(1), b = compressingGas(2);
  a.run(4000);
  b.run(4000);
  ASSERT_GT(a.contacts().activeCount(), 1000u) << "the test must exercise many contacts";
  ASSERT_GT(a.profile().rebuilds, 2);
  expectSameBits(a, b);
  EXPECT_EQ(a.energy().frictionWork, b.energy().frictionWork);
}

// The common case of the cyclic stages (no local damping, no contact damping, no energy terms in the law's
// block): 1 to 4 threads, where 3 and 4 split the chunks unevenly.
TEST(Determinism, WithoutDampingOneToFourThreadsGiveIdenticalBits) {
  Simulation a = compressingGas(1, 0.0, 1.0, false);
  a.run(4000);
  ASSERT_GT(a.contacts().activeCount(), 1000u) << "the test must exercise many contacts";
  ASSERT_GT(a.profile().rebuilds, 2);
  for (int threads : {2, 3, 4}) {
    SCOPED_TRACE(threads);
    Simulation b = compressingGas(threads, 0.0, 1.0, false);
    b.run(4000);
    expectSameBits(a, b);
  }
}

// With local and contact damping on, the whole energy ledger (not only the trajectory) has the same bits for
// 1, 2 and 3 threads: the dissipated works are summed per fixed chunk of pairs or particles, in chunk order,
// whichever thread computed a chunk (3 threads split the 16 particle chunks and the pair chunks unevenly).
TEST(Determinism, LocalDampingWorkHasTheSameBitsForOneToThreeThreads) {
  Simulation a = compressingGas(1);
  a.run(3000);
  ASSERT_GT(a.energy().localDampingWork, 0.0) << "the test must exercise the local damping";
  for (int threads : {2, 3}) {
    SCOPED_TRACE(threads);
    Simulation b = compressingGas(threads);
    b.run(3000);
    expectSameBits(a, b);
    test::expectSameEnergy(a, b);
  }
}

// The parallel loops balance their runs between the threads as they go (core/work_stealing.hpp), so which thread
// computes a pair or moves a particle changes from step to step. Eight threads on this test's cores leave some
// of them waiting for a core, and the others take their runs: the bits are still those of one thread.
TEST(Determinism, RunsTakenFromAnotherThreadGiveTheSameBits) {
  Simulation a = compressingGas(1, 0.0, 1.0, false);
  a.run(4000);
  Simulation b = compressingGas(8, 0.0, 1.0, false);
  b.run(4000);
  ASSERT_GT(a.contacts().activeCount(), 1000u) << "the test must exercise many contacts";
  EXPECT_EQ(a.profile().stolenRuns, 0) << "one thread takes its whole share";
  EXPECT_GT(b.profile().stolenRuns, 0) << "the test must exercise runs taken from another thread";
  // and the halo and seeds (core/thread_boundary.hpp), which a stolen run reads and writes too
  EXPECT_TRUE(b.threadBoundary().exchange);
  EXPECT_GT(b.threadBoundary().halo.size(), 0u);
  EXPECT_GT(b.threadBoundary().seedParticle.size(), 1u);
  expectSameBits(a, b);
}

// The threads' shares follow their measured costs (core/share_balance.hpp) and so differ from run to run; any
// edges give the bits of one thread. Skewed fixed shares, changed in the middle of a run (the boundary is made
// again at the next pass, its halo and seeds with it), against one thread; then the measured shares, made again
// at least once here because their first window of steps is taken on a boundary with equal shares.
TEST(Determinism, SkewedAndMeasuredSharesGiveTheSameBits) {
  Simulation a = compressingGas(1, 0.0, 1.0, false);
  a.run(4000);
  ASSERT_GT(a.contacts().activeCount(), 1000u) << "the test must exercise many contacts";
  Simulation b = compressingGas(2, 0.0, 1.0, false);
  b.setFixedShares({1.0, 4.0});
  b.run(3200);
  const std::size_t firstEdge = b.threadBoundary().chunkBegin.at(1);
  b.setFixedShares({4.0, 1.0});
  b.run(800);
  const std::size_t secondEdge = b.threadBoundary().chunkBegin.at(1);
  const std::size_t chunks = b.threadBoundary().chunkBegin.back();
  EXPECT_LT(firstEdge, chunks / 3) << "the first thread's share is a fifth";
  EXPECT_GT(secondEdge, 2 * chunks / 3) << "then four fifths";
  EXPECT_TRUE(b.threadBoundary().exchange);
  expectSameBits(a, b);

  Simulation c = compressingGas(3, 0.0, 1.0, false);  // measured (the default)
  c.run(4000);
  EXPECT_TRUE(c.shareBalance().measuring());
  EXPECT_EQ(c.shareBalance().costs().size(), 3u) << "the windows measured every thread";
  expectSameBits(a, c);
}
