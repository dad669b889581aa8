// The threads' shares from their measured costs (core/share_balance.hpp): the step-time prediction in closed form,
// the edges that minimise it, the fixed shares' edges, and the windows that move the edges only when the
// prediction gains more than kMinGain. That the edges never change the bits: tests/determinism_test.cpp.
#include <gtest/gtest.h>

#include "core/share_balance.hpp"
#include "core/work_stealing.hpp"

using namespace fl;

namespace {
// chunks + 1 first particles, `perChunk` particles in every chunk
std::vector<std::size_t> uniformParticles(std::size_t chunks, std::size_t perChunk) {
  std::vector<std::size_t> first(chunks + 1);
  for (std::size_t k = 0; k <= chunks; ++k) first[k] = k * perChunk;
  return first;
}

// one window of `steps` steps of two threads: thread t takes chunkCost[t] a chunk and particleCost[t] a particle
void feedWindow(ShareBalance& b, const std::vector<std::size_t>& edges, const std::vector<std::size_t>& first,
                const double chunkCost[2], const double particleCost[2]) {
  for (long s = 0; s < ShareBalance::kWindowSteps; ++s) {
    for (int t = 0; t < 2; ++t) {
      const std::size_t chunks = edges[t + 1] - edges[t], particles = first[edges[t + 1]] - first[edges[t]];
      b.addPass(t, chunkCost[t] * static_cast<double>(chunks), chunks);
      b.addKick(t, particleCost[t] * static_cast<double>(particles), particles);
    }
    const bool windowEnds = b.endStep();
    ASSERT_EQ(windowEnds, s + 1 == ShareBalance::kWindowSteps) << "step " << s;
  }
}
}  // namespace

TEST(ShareBalance, PredictedStepIsTheSlowestPassPlusTheSlowestKick) {
  // 10 chunks; particles 0, 10, ..., 100 except that chunk 9 holds 30 particles
  std::vector<std::size_t> first = uniformParticles(10, 10);
  first[10] = 120;
  const std::vector<ThreadCosts> cost{{2.0, 0.5}, {1.0, 0.25}};
  // edges 0 | 4 | 10: thread 0 has 4 chunks, 40 particles; thread 1 6 chunks, 80 particles
  const double time = predictedStep(cost, {0, 4, 10}, first);
  EXPECT_DOUBLE_EQ(time, std::max(2.0 * 4, 1.0 * 6) + std::max(0.5 * 40, 0.25 * 80));
  EXPECT_DOUBLE_EQ(predictedStep(cost, {0, 2, 10}, first), std::max(4.0, 8.0) + std::max(10.0, 25.0));
}

TEST(ShareBalance, TwoThreadsTakeTheEdgeThatBalancesThem) {
  const std::vector<std::size_t> first = uniformParticles(48, 80);
  // equal costs: the middle
  EXPECT_EQ(bestEdges({{1.0, 0.01}, {1.0, 0.01}}, first, {0, 24, 48}), (std::vector<std::size_t>{0, 24, 48}));
  EXPECT_EQ(bestEdges({{1.0, 0.01}, {1.0, 0.01}}, first, {0, 5, 48}), (std::vector<std::size_t>{0, 24, 48}));
  // the first thread twice as slow at both loops: a third of the chunks
  const std::vector<ThreadCosts> slowFirst{{2.0, 0.02}, {1.0, 0.01}};
  const std::vector<std::size_t> best = bestEdges(slowFirst, first, {0, 24, 48});
  EXPECT_EQ(best, (std::vector<std::size_t>{0, 16, 48}));
  // and no edge predicts less
  for (std::size_t k = 1; k < 48; ++k)
    EXPECT_GE(predictedStep(slowFirst, {0, k, 48}, first), predictedStep(slowFirst, best, first)) << k;
}

TEST(ShareBalance, MoreThreadsMoveEdgesWhileThePredictionImproves) {
  const std::vector<std::size_t> first = uniformParticles(60, 10);
  const std::vector<ThreadCosts> cost{{1.0, 0.1}, {2.0, 0.2}, {1.0, 0.1}};
  const std::vector<std::size_t> start{0, 20, 40, 60};
  const std::vector<std::size_t> best = bestEdges(cost, first, start);
  ASSERT_EQ(best.size(), 4u);
  EXPECT_EQ(best.front(), 0u);
  EXPECT_EQ(best.back(), 60u);
  for (std::size_t t = 0; t < 3; ++t) EXPECT_LT(best[t], best[t + 1]) << "every thread keeps a chunk";
  // the slow middle thread gets half the chunks of each other one: 24 | 12 | 24
  EXPECT_EQ(best, (std::vector<std::size_t>{0, 24, 36, 60}));
  EXPECT_LT(predictedStep(cost, best, first), predictedStep(cost, start, first));
}

TEST(ShareBalance, FixedSharesGiveTheNearestChunks) {
  EXPECT_EQ(chunkBeginFor({}, 2, 51), (std::vector<std::size_t>{0, staticBegin(1, 2, 51), 51}));
  EXPECT_EQ(chunkBeginFor({1.0, 1.0, 1.0}, 3, 10), (std::vector<std::size_t>{0, 3, 7, 10}));  // the nearest
  EXPECT_EQ(chunkBeginFor({1.0, 3.0}, 2, 40), (std::vector<std::size_t>{0, 10, 40}));
  EXPECT_EQ(chunkBeginFor({0.0, 1.0}, 2, 40), (std::vector<std::size_t>{0, 1, 40})) << "at least one chunk";
  EXPECT_EQ(chunkBeginFor({1.0, 0.0}, 2, 40), (std::vector<std::size_t>{0, 39, 40}));
  EXPECT_EQ(chunkBeginFor({1.0, 3.0}, 2, 1), (std::vector<std::size_t>{0, 1, 1})) << "fewer chunks than threads";
}

TEST(ShareBalance, WindowsMoveTheEdgesOnlyForAGain) {
  const std::vector<std::size_t> first = uniformParticles(48, 80);
  const std::vector<std::size_t> even{0, 24, 48};
  ShareBalance b;
  b.prepare(2);
  EXPECT_EQ(b.edges(2, first), even) << "equal shares before the first window";
  // equal threads: the window keeps the edges
  const double equalChunk[2] = {3e-6, 3e-6}, equalParticle[2] = {16e-9, 16e-9};
  feedWindow(b, even, first, equalChunk, equalParticle);
  EXPECT_FALSE(b.reconsider(even, first));
  EXPECT_EQ(b.edges(2, first), even);
  // a thread 1 % slower: within kMinGain, the edges stay
  const double nearChunk[2] = {3.03e-6, 3e-6}, nearParticle[2] = {16.16e-9, 16e-9};
  feedWindow(b, even, first, nearChunk, nearParticle);
  EXPECT_FALSE(b.reconsider(even, first));
  // the first thread 1.4x slower, as a slow vCPU was: the next edges give it less, and are taken
  const double slowChunk[2] = {4.2e-6, 3e-6}, slowParticle[2] = {22.4e-9, 16e-9};
  feedWindow(b, even, first, slowChunk, slowParticle);
  EXPECT_TRUE(b.reconsider(even, first)) << "smoothed, half of the way there already pays";
  const std::vector<std::size_t> moved = b.edges(2, first);
  EXPECT_LT(moved[1], 24u);
  std::vector<std::size_t> edges = moved;
  for (int w = 0; w < 10; ++w) {  // the smoothed costs converge on the window's
    feedWindow(b, edges, first, slowChunk, slowParticle);
    if (b.reconsider(edges, first)) edges = b.edges(2, first);
  }
  EXPECT_EQ(edges[1], 20u) << "4.2 x = 3 (48 - x) chunks";
  EXPECT_NEAR(b.costs()[0].perChunk, 4.2e-6, 0.01e-6);
  // fixed shares: no measuring, the shares' edges
  b.fix({1.0, 3.0});
  EXPECT_FALSE(b.measuring());
  EXPECT_FALSE(b.endStep());
  EXPECT_EQ(b.edges(2, first), (std::vector<std::size_t>{0, 12, 48}));
  b.measure();
  b.prepare(2);
  EXPECT_EQ(b.edges(2, first), even) << "measured again from scratch";
}

// A pass that is not timed (the Mindlin–Deresiewicz law's) leaves the kick's costs alone to balance; a window in
// which a thread kicked nothing moves nothing.
TEST(ShareBalance, WindowsWithoutThePassBalanceTheKick) {
  const std::vector<std::size_t> first = uniformParticles(48, 80);
  const std::vector<std::size_t> even{0, 24, 48};
  ShareBalance b;
  b.prepare(2);
  for (long s = 0; s < ShareBalance::kWindowSteps; ++s) {
    b.addKick(0, 2e-6, 1000);
    b.endStep();
  }
  EXPECT_FALSE(b.reconsider(even, first)) << "the second thread kicked nothing";
  EXPECT_TRUE(b.costs().empty());
  for (int w = 0; w < 10; ++w) {
    for (long s = 0; s < ShareBalance::kWindowSteps; ++s) {
      b.addKick(0, 30e-6, 1000);  // 30 ns a particle
      b.addKick(1, 20e-6, 1000);  // 20 ns
      b.endStep();
    }
    b.reconsider(even, first);
  }
  ASSERT_EQ(b.costs().size(), 2u);
  EXPECT_EQ(b.costs()[0].perChunk, 0.0);
  EXPECT_EQ(b.edges(2, first)[1], 19u) << "30 x = 20 (48 - x) particles' chunks, nearest 19.2";
}
