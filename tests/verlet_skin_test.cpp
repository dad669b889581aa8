// The automatic Verlet skin (core/verlet_skin.hpp): the rule in closed form, and in a simulation: it narrows on
// a quiet packing and widens again when the particles move, it never misses a contact (every touching pair of
// a brute-force search is a contact of the list), a fixed skin stays fixed, and the results stay the same for
// any thread count and across a checkpoint that falls just before a check.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "core/binary_io.hpp"
#include "core/neighbor_search.hpp"
#include "core/verlet_skin.hpp"
#include "test_support.hpp"

namespace fl {
namespace {

constexpr double kD = 1.1e-3;  // a mean diameter [m]

// A list of skin 0.1 d that lived 2000 steps, its bound grown by 20 µm, 1.42 gap pairs a particle (the dense
// benchmark's at that skin).
verlet_skin::ListStats aList() { return {0.1 * kD, 2000, 20e-6, 1.42}; }

TEST(VerletSkinRule, OptimumIsTheSquareRootOfRebuildCostTimesRateOverGapDensity) {
  // s* = sqrt(ρ ů / g): ů = 1e-8 m a step, g = 1.42 / 0.11 mm
  const double g = 1.42 / (0.1 * kD);
  EXPECT_DOUBLE_EQ(verlet_skin::optimal(aList(), kD), std::sqrt(verlet_skin::kRebuildCost * 1e-8 / g));
  EXPECT_NEAR(verlet_skin::optimal(aList(), kD), 10.8e-6, 0.05e-6);
  // four times the rate: twice the skin; four times the gaps (a denser packing): half
  verlet_skin::ListStats faster = aList(), denser = aList();
  faster.used *= 4.0;
  denser.gapPairs *= 4.0;
  EXPECT_DOUBLE_EQ(verlet_skin::optimal(faster, kD), 2.0 * verlet_skin::optimal(aList(), kD));
  EXPECT_DOUBLE_EQ(verlet_skin::optimal(denser, kD), 0.5 * verlet_skin::optimal(aList(), kD));
  // the same gaps on a list half as wide are a density twice as high
  verlet_skin::ListStats narrower = aList();
  narrower.skin *= 0.5;
  EXPECT_DOUBLE_EQ(verlet_skin::optimal(narrower, kD), std::sqrt(0.5) * verlet_skin::optimal(aList(), kD));
}

TEST(VerletSkinRule, ClampedToItsRangeOfTheMeanDiameter) {
  verlet_skin::ListStats still = aList(), gas = aList(), fresh = aList(), noGaps = aList();
  still.used = 0.0;       // nothing moved
  gas.used = 1e-2;        // everything moved far
  fresh.steps = 0;        // no step
  noGaps.gapPairs = 0.0;  // every listed pair touches: nothing to save
  EXPECT_DOUBLE_EQ(verlet_skin::optimal(still, kD), verlet_skin::kMinFraction * kD);
  EXPECT_DOUBLE_EQ(verlet_skin::optimal(gas, kD), verlet_skin::kMaxFraction * kD);
  EXPECT_DOUBLE_EQ(verlet_skin::optimal(fresh, kD), verlet_skin::kMaxFraction * kD);
  EXPECT_DOUBLE_EQ(verlet_skin::optimal(noGaps, kD), verlet_skin::kMaxFraction * kD);
}

TEST(VerletSkinRule, ChecksAtPowersOfTwoFrom64StepsAndOnlyForAFactorTwo) {
  EXPECT_FALSE(verlet_skin::isCheckStep(0));
  EXPECT_FALSE(verlet_skin::isCheckStep(32));
  EXPECT_FALSE(verlet_skin::isCheckStep(63));
  EXPECT_TRUE(verlet_skin::isCheckStep(64));
  EXPECT_FALSE(verlet_skin::isCheckStep(96));
  EXPECT_TRUE(verlet_skin::isCheckStep(1024));
  EXPECT_FALSE(verlet_skin::isCheckStep(1536));
  EXPECT_TRUE(verlet_skin::isCheckStep(2048));
  EXPECT_TRUE(verlet_skin::isCheckStep(1L << 20));
  // ů = 1e-8 m a step, 1.42 gap pairs a particle: a 20 µm list's optimum is sqrt(ρ ů 20 µm / 1.42) = 4.6 µm,
  // less than half of it; a 4 µm list's is 2.1 µm, clamped to 0.002 d = 2.2 µm: more than half
  verlet_skin::ListStats list = aList();
  list.steps = 2048;
  list.used = 2048 * 1e-8;
  list.skin = 20e-6;
  EXPECT_NEAR(verlet_skin::optimal(list, kD), 4.6e-6, 0.05e-6);
  EXPECT_TRUE(verlet_skin::tooWide(list, kD));
  list.steps = 2049;  // not a check step
  list.used = 2049 * 1e-8;
  EXPECT_FALSE(verlet_skin::tooWide(list, kD));
  list.steps = 32;
  list.used = 32 * 1e-8;
  EXPECT_FALSE(verlet_skin::tooWide(list, kD));
  list.steps = 2048;
  list.used = 2048 * 1e-8;
  list.skin = 4e-6;
  EXPECT_DOUBLE_EQ(verlet_skin::optimal(list, kD), verlet_skin::kMinFraction * kD);
  EXPECT_FALSE(verlet_skin::tooWide(list, kD));
}

// Touching pairs by brute force (a search with skin 0) against the list's contacts.
std::size_t touchingByBruteForce(const Simulation& sim) {
  const PairList all = findPairsBruteForce(sim.particles(), sim.cell(), 0.0);
  return all.first.size();
}

double meanDiameterOf(const Simulation& sim) {
  double d = 0.0;
  for (double r : sim.particles().radius) d += 2.0 * r;
  return d / static_cast<double>(sim.particles().size());
}

// The compressing gas of the determinism tests, then held still and damped: a packing that moves less and less.
// skin 0: the automatic skin.
Simulation quietingPacking(int threads, double skin = 0.0) {
  NumericsSettings num;
  num.threads = threads;
  num.skin = skin;
  num.restitution = 0.5;
  num.localDamping = 0.05;
  Simulation sim = test::compressingGasWith(800, num);
  sim.run(3000);
  sim.setVelocityGradient(Mat3::Zero());
  sim.setLocalDamping(0.7);
  return sim;
}

TEST(VerletSkin, NarrowsAsTheParticlesSlowDownAndNeverMissesAContact) {
  Simulation sim = quietingPacking(1);
  const double meanD = meanDiameterOf(sim);
  const long rebuildsBefore = sim.profile().rebuilds;
  double narrowest = sim.skin();
  for (int k = 0; k < 24; ++k) {
    sim.run(250);
    narrowest = std::min(narrowest, sim.skin());
    ASSERT_GE(sim.skin(), verlet_skin::kMinFraction * meanD * (1 - 1e-12));
    ASSERT_LE(sim.skin(), verlet_skin::kMaxFraction * meanD * (1 + 1e-12));
    ASSERT_EQ(sim.contacts().activeCount(), touchingByBruteForce(sim)) << "after " << (k + 1) * 250 << " steps";
  }
  EXPECT_LT(narrowest, 0.4 * verlet_skin::kMaxFraction * meanD) << "the skin should narrow as the gas slows down";
  EXPECT_GT(sim.profile().rebuilds, rebuildsBefore);
}

TEST(VerletSkin, WidensAgainWhenTheParticlesMove) {
  Simulation sim = quietingPacking(1);
  sim.run(5000);
  const double quiet = sim.skin();
  // compress again, fast: the displacements use the narrow skin up within a few steps
  Mat3 L = Mat3::Zero();
  L.diagonal() = Vec3(-400, -400, -500);
  sim.setVelocityGradient(L);
  sim.setLocalDamping(0.05);
  double widest = quiet;
  for (int k = 0; k < 10; ++k) {
    sim.run(100);
    widest = std::max(widest, sim.skin());
    ASSERT_EQ(sim.contacts().activeCount(), touchingByBruteForce(sim)) << "after " << (k + 1) * 100 << " steps";
  }
  EXPECT_GT(widest, 2.0 * quiet);
  EXPECT_GT(sim.contacts().activeCount(), 1500u);
}

TEST(VerletSkin, AFixedSkinStaysFixed) {
  Simulation sim = quietingPacking(1, 0.07e-3);
  sim.run(5000);
  ASSERT_GT(sim.profile().rebuilds, 0);
  EXPECT_EQ(sim.skin(), 0.07e-3);
}

// A rebuild writes the new list into the arrays it has (core/huge_pages.hpp: fitCapacity; docs/performance.md,
// fortieth session). Rebuilt again and again on the same positions (refresh(): the same list each time), the
// pass's results and the history stay where they are, and the pair definitions take turns in two sets of arrays
// (the history's carry-over itself: tests/history_carry_test.cpp). Over a moving run the list's length drifts,
// and a refit is right when it leaves the kept range: that depends on the trajectory, which differs between
// compilers, so the test does not move the particles.
TEST(VerletSkin, RebuildsReuseTheirArrays) {
  Simulation sim = quietingPacking(2, 0.02e-3);
  sim.run(500);
  sim.refresh();  // a first rebuild may refit arrays sized for an earlier, longer list
  sim.refresh();
  const ContactStore& c = sim.contacts();
  const PairResult* results = c.result.data();
  const ContactHistory* history = c.history.data();
  const std::size_t pairs = c.size();
  ASSERT_GT(pairs, 500u);
  std::set<const std::int32_t*> firsts{c.first.data()};
  for (int k = 0; k < 6; ++k) {
    sim.refresh();
    ASSERT_EQ(c.size(), pairs);
    EXPECT_EQ(c.result.data(), results) << "after refresh " << k;
    EXPECT_EQ(c.history.data(), history) << "after refresh " << k;
    firsts.insert(c.first.data());
  }
  EXPECT_EQ(firsts.size(), 2u);
  EXPECT_EQ(c.activeCount(), touchingByBruteForce(sim));
}

TEST(VerletSkin, SameBitsForAnyThreadCountAndAcrossACheckpoint) {
  Simulation a = quietingPacking(1), b = quietingPacking(2);
  a.run(2000);
  BinaryWriter w;
  a.saveState(w);  // the list's clock is saved: the restored run checks at the same steps
  a.run(3000);
  b.run(5000);
  ASSERT_LT(a.skin(), 0.5 * verlet_skin::kMaxFraction * meanDiameterOf(a)) << "the runs must cross a narrowing";
  test::expectSameBits(a, b);
  BinaryReader r(w.bytes(), "memory");
  Simulation c = Simulation::restoreState(r);
  c.run(3000);
  test::expectSameBits(a, c);
  EXPECT_EQ(a.skin(), c.skin());
}

}  // namespace
}  // namespace fl
