// The threads' shares and what crosses between them (core/thread_boundary.hpp): every partner a pass reads
// from another share has a halo slot its owner fills, in the order the pairs first read them and before the
// reader's block waits for it, every seed covers exactly the leading adjacency entries
// that one other thread computed, and the kick's own entries are all of its own share. The bits of the
// halo and seed paths are checked against one thread by tests/determinism_test.cpp.
#include <gtest/gtest.h>

#include "core/simulation.hpp"
#include "core/thread_boundary.hpp"
#include "test_support.hpp"

using namespace fl;

namespace {
constexpr std::size_t kChunk = 256;  // as Simulation's

// a compressed gas with a few thousand listed pairs
const ContactStore& denseContacts(Simulation& sim) {
  Mat3 L = Mat3::Zero();
  L.diagonal() = Vec3(-400, -400, -500);
  sim.setVelocityGradient(L);
  sim.run(3000);
  return sim.contacts();
}

Simulation gas() {
  Packing pk = test::stirredGas(1500, 0.35, 11, 3);
  NumericsSettings num;
  num.localDamping = 0.05;
  return Simulation(std::move(pk.particles), pk.cell, {Material::paperGlass()}, num);
}

void checkBoundary(const ContactStore& c, std::size_t n, int nt, const std::vector<std::size_t>& edges = {}) {
  SCOPED_TRACE(nt);
  const ThreadBoundary b = buildThreadBoundary(c, n, nt, kChunk, true, edges);
  ASSERT_EQ(b.threads, nt);
  ASSERT_TRUE(b.exchange);
  ASSERT_EQ(b.begin.front(), 0u);
  ASSERT_EQ(b.begin.back(), n);
  for (int t = 0; t < nt; ++t) ASSERT_LE(b.begin[t], b.begin[t + 1]);
  std::vector<int> owner(n), passThread((c.size() + kChunk - 1) / kChunk);
  for (int t = 0; t < nt; ++t) {
    for (std::size_t i = b.begin[t]; i < b.begin[t + 1]; ++i) owner[i] = t;
    for (std::size_t k = b.chunkBegin[t]; k < b.chunkBegin[t + 1]; ++k) passThread[k] = t;
  }
  const auto by = [&](std::int32_t entry) { return passThread[static_cast<std::size_t>(entry >> 1) / kChunk]; };
  // halo: exactly the partners another share's pass reads, each in its owner's range of slots
  std::vector<char> read(n, 0);
  for (std::size_t p = 0; p < c.size(); ++p) {
    const int j = c.second[p], t = passThread[p / kChunk];
    if (owner[j] == t) {
      EXPECT_EQ(b.partner[p], j) << "pair " << p;
      continue;
    }
    read[j] = 1;
    ASSERT_GE(b.partner[p], static_cast<std::int32_t>(n)) << "pair " << p;
    const std::size_t slot = static_cast<std::size_t>(b.partner[p]) - n;
    ASSERT_LT(slot, b.halo.size());
    EXPECT_EQ(b.halo[slot], j);
    EXPECT_GE(slot, b.haloBegin[owner[j]]);
    EXPECT_LT(slot, b.haloBegin[owner[j] + 1]);
  }
  std::size_t readCount = 0;
  for (char r : read) readCount += r != 0;
  EXPECT_EQ(b.halo.size(), readCount) << "a slot no other thread reads";
  EXPECT_GT(b.halo.size(), 0u);
  // seeds: the leading entries of one other thread, and nothing of another after them
  ASSERT_EQ(b.seedEntryBegin.size(), b.seedParticle.size() + 1);  // each slot's entries, and the zero seed's
  std::size_t seeded = 0, foreignUnseeded = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t e0 = c.adjStart[i], e1 = c.adjStart[i + 1], k = b.kickBegin[i];
    if (b.seedOf[i] == 0) {
      EXPECT_EQ(k, e0) << "particle " << i;
      for (std::int32_t e = e0; e < e1; ++e) foreignUnseeded += by(c.adjEntry[e]) != owner[i];
      continue;
    }
    ++seeded;
    const auto s = static_cast<std::size_t>(b.seedOf[i]);
    ASSERT_LT(s, b.seedParticle.size());
    EXPECT_EQ(b.seedParticle[s], static_cast<std::int32_t>(i));
    ASSERT_GT(k, e0) << "an empty seed, particle " << i;
    ASSERT_LE(k, e1);
    const int t = by(c.adjEntry[e0]);
    EXPECT_NE(t, owner[i]);
    EXPECT_GE(s, b.seedBegin[t]);
    EXPECT_LT(s, b.seedBegin[t + 1]);
    for (std::int32_t e = e0; e < k; ++e) EXPECT_EQ(by(c.adjEntry[e]), t) << "particle " << i;
    // the seed's sum walks its own copy of those entries, in the same order
    ASSERT_EQ(b.seedEntryBegin[s + 1] - b.seedEntryBegin[s], k - e0) << "particle " << i;
    for (std::int32_t e = e0; e < k; ++e)
      EXPECT_EQ(b.seedEntry[static_cast<std::size_t>(b.seedEntryBegin[s] + (e - e0))], c.adjEntry[e]) << "particle " << i;
    for (std::int32_t e = k; e < e1; ++e) EXPECT_EQ(by(c.adjEntry[e]), owner[i]) << "particle " << i;
  }
  EXPECT_GT(seeded, 0u);
  EXPECT_EQ(seeded + 1, b.seedParticle.size());
  EXPECT_EQ(b.seedEntryBegin[0], b.seedEntryBegin[1]) << "the zero seed sums nothing";
  EXPECT_EQ(static_cast<std::size_t>(b.seedEntryBegin.back()), b.seedEntry.size());
  // the kick's list of seeded particles: every one, ascending, then an index past every particle
  ASSERT_EQ(b.seeded.size(), seeded + 1);
  for (std::size_t q = 0; q + 1 < b.seeded.size(); ++q) {
    EXPECT_NE(b.seedOf[static_cast<std::size_t>(b.seeded[q])], 0) << "listed without a seed: " << b.seeded[q];
    if (q > 0) {
      EXPECT_LT(b.seeded[q - 1], b.seeded[q]);
    }
  }
  EXPECT_GE(b.seeded.back(), static_cast<std::int32_t>(n));
  // the pass's words of halo pairs: bit p of block p / 64 set exactly where pair p reads a halo slot
  ASSERT_EQ(b.haloPairs.size(), (c.size() + ThreadBoundary::kHaloBlock - 1) / ThreadBoundary::kHaloBlock);
  for (std::size_t p = 0; p < c.size(); ++p) {
    const bool bit = (b.haloPairs[p / ThreadBoundary::kHaloBlock] >> (p % ThreadBoundary::kHaloBlock)) & 1u;
    EXPECT_EQ(bit, b.partner[p] >= static_cast<std::int32_t>(n)) << "pair " << p;
  }
  for (std::size_t p = c.size(); p < b.haloPairs.size() * ThreadBoundary::kHaloBlock; ++p)
    EXPECT_EQ((b.haloPairs.back() >> (p % ThreadBoundary::kHaloBlock)) & 1u, 0u) << "a bit past the last pair";
  // the order an owner copies its slots in: that of the pairs that first read them; and what a reader waits
  // for before a block: every slot that block and the next read, counted from the start of its owner's group
  ASSERT_EQ(b.haloNeed.size(), b.haloPairs.size());
  std::vector<std::size_t> firstRead(b.halo.size(), c.size());
  for (std::size_t p = 0; p < c.size(); ++p) {
    if (b.partner[p] < static_cast<std::int32_t>(n)) continue;
    const std::size_t slot = static_cast<std::size_t>(b.partner[p]) - n;
    firstRead[slot] = std::min(firstRead[slot], p);
    const std::size_t place = slot - b.haloBegin[owner[b.halo[slot]]];
    const std::size_t block = p / ThreadBoundary::kHaloBlock;
    EXPECT_LT(place, b.haloNeed[block]) << "pair " << p << " reads a slot its block does not wait for";
    if (block > 0) {
      EXPECT_LT(place, b.haloNeed[block - 1]) << "pair " << p << " is prefetched before its slot is waited for";
    }
  }
  for (int t = 0; t < nt; ++t)
    for (std::size_t q = b.haloBegin[t]; q + 1 < b.haloBegin[t + 1]; ++q)
      EXPECT_LT(firstRead[q], firstRead[q + 1]) << "owner " << t << ", slot " << q;
  // with two shares only the first particle of the second share can keep foreign entries unseeded (its
  // own pairs straddle the split): at most its entries
  if (nt == 2) {
    const std::size_t f = b.begin[1];
    EXPECT_LE(foreignUnseeded, static_cast<std::size_t>(c.adjStart[f + 1] - c.adjStart[f]));
  }
}
}  // namespace

TEST(ThreadBoundary, OneThreadExchangesNothing) {
  Simulation sim = gas();
  const ContactStore& c = denseContacts(sim);
  const ThreadBoundary b = buildThreadBoundary(c, sim.particles().size(), 1, kChunk);
  EXPECT_FALSE(b.exchange);
  EXPECT_EQ(b.begin, (std::vector<std::size_t>{0, sim.particles().size()}));
  EXPECT_TRUE(b.halo.empty());
  EXPECT_EQ(b.seedParticle.size(), 1u);  // the zero seed
}

TEST(ThreadBoundary, HaloAndSeedsCoverWhatCrossesForTwoToFourThreads) {
  Simulation sim = gas();
  const ContactStore& c = denseContacts(sim);
  ASSERT_GT(c.size(), 4 * kChunk) << "the test must give every thread pair chunks";
  for (int nt : {2, 3, 4}) checkBoundary(c, sim.particles().size(), nt);
}

// The shares' edges measured from the threads' costs (core/share_balance.hpp): the chunks split where given, the
// particles at the first particle of each share's first chunk, and the halo and seeds whole for any edges.
TEST(ThreadBoundary, GivenEdgesSplitTheChunksThere) {
  Simulation sim = gas();
  const ContactStore& c = denseContacts(sim);
  const std::size_t n = sim.particles().size(), chunks = (c.size() + kChunk - 1) / kChunk;
  ASSERT_GT(chunks, 6u);
  for (const std::vector<std::size_t>& edges : {std::vector<std::size_t>{0, 1, chunks},
                                                 std::vector<std::size_t>{0, chunks - 2, chunks},
                                                 std::vector<std::size_t>{0, 1, 2, chunks}}) {
    const int nt = static_cast<int>(edges.size()) - 1;
    SCOPED_TRACE(edges[1]);
    const ThreadBoundary b = buildThreadBoundary(c, n, nt, kChunk, true, edges);
    EXPECT_EQ(b.chunkBegin, edges);
    for (int t = 1; t < nt; ++t) EXPECT_EQ(b.begin[t], static_cast<std::size_t>(c.first[kChunk * edges[t]]));
    checkBoundary(c, n, nt, edges);
  }
  // edges of another list (another chunk count) are not used: the static split
  const ThreadBoundary stale = buildThreadBoundary(c, n, 2, kChunk, true, {0, 1, chunks + 1});
  EXPECT_EQ(stale.chunkBegin, (std::vector<std::size_t>{0, staticBegin(1, 2, chunks), chunks}));
}

TEST(ThreadBoundary, FewerChunksThanThreadsSplitsStatically) {
  Simulation sim = test::twoSpheres(0.5e-3, 0.5e-3, Vec3(1e-3, 1e-3, 1e-3), Vec3(1.9e-3, 1e-3, 1e-3), Vec3::Zero(),
                                    Vec3::Zero(), Material::paperGlass(), NumericsSettings{}, 0.01);
  const ThreadBoundary b = buildThreadBoundary(sim.contacts(), sim.particles().size(), 2, kChunk);
  EXPECT_FALSE(b.exchange);
  EXPECT_EQ(b.begin, (std::vector<std::size_t>{0, 1, 2}));
}

// States that outgrow the caches keep the aligned shares but exchange nothing (Simulation passes halo = false
// from kLargeStateFrom particles): the same shares, every partner read in place, no seeds.
TEST(ThreadBoundary, WithoutHaloTheSharesStayAligned) {
  Simulation sim = gas();
  const ContactStore& c = denseContacts(sim);
  const std::size_t n = sim.particles().size();
  for (int nt : {2, 3}) {
    SCOPED_TRACE(nt);
    const ThreadBoundary with = buildThreadBoundary(c, n, nt, kChunk, true);
    const ThreadBoundary without = buildThreadBoundary(c, n, nt, kChunk, false);
    ASSERT_TRUE(with.exchange);
    EXPECT_FALSE(without.exchange);
    EXPECT_EQ(without.begin, with.begin);
    EXPECT_EQ(without.chunkBegin, with.chunkBegin);
    EXPECT_NE(without.begin[1], staticBegin(1, nt, n)) << "the test must tell the aligned split from the static one";
    EXPECT_TRUE(without.halo.empty());
    EXPECT_TRUE(without.partner.empty());
    EXPECT_EQ(without.seedParticle.size(), 1u);
  }
}
