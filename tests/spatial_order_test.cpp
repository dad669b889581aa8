// Morton (Z-order) sorting of a packing (core/spatial_order.hpp): the code has the closed-form bit
// interleaving, sorting is a permutation that carries every per-particle field with its id, leaves the
// physical neighbour pairs unchanged, and brings pair partners close in memory.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include "core/errors.hpp"
#include "core/gas_generator.hpp"
#include "core/neighbor_search.hpp"
#include "core/simulation.hpp"
#include "core/spatial_order.hpp"

using namespace fl;

namespace {
Packing gas(int count, double solidFraction, std::uint64_t seed) {
  GasSpec g;
  g.count = count;
  g.solidFraction = solidFraction;
  g.seed = seed;
  return generateGas(g);
}
}  // namespace

TEST(SpatialOrder, MortonCodeInterleavesTenBitsPerAxis) {
  const double q = 1.0 / 1024.0;
  EXPECT_EQ(mortonCode(Vec3(0, 0, 0)), 0u);
  EXPECT_EQ(mortonCode(Vec3(q, 0, 0)), 1u);
  EXPECT_EQ(mortonCode(Vec3(0, q, 0)), 2u);
  EXPECT_EQ(mortonCode(Vec3(0, 0, q)), 4u);
  EXPECT_EQ(mortonCode(Vec3(2 * q, 0, 0)), 8u);
  EXPECT_EQ(mortonCode(Vec3(3 * q, 5 * q, 0)), 139u);  // x = 011 -> bits 0, 3; y = 101 -> bits 1, 7
  EXPECT_EQ(mortonCode(Vec3(1 - q / 2, 1 - q / 2, 1 - q / 2)), (1u << 30) - 1);
  // reduced coordinates are wrapped into [0, 1); non-finite ones map to 0 rather than to undefined casts
  EXPECT_EQ(mortonCode(Vec3(1 + q, -1 + 2 * q, 2)), mortonCode(Vec3(q, 2 * q, 0)));
  EXPECT_EQ(mortonCode(Vec3(std::nan(""), 0, 0)), 0u);
}

TEST(SpatialOrder, SortingIsAPermutationThatKeepsParticlesAndPairs) {
  Packing pk = gas(800, 0.3, 7);
  for (std::size_t i = 0; i < pk.particles.size(); ++i) {  // distinct velocities and spins to follow
    pk.particles.vel[i] = Vec3(double(i), 0.5 * double(i), -double(i));
    pk.particles.angVel[i] = Vec3(0, double(i), 1);
  }
  const ParticleStore before = pk.particles;
  ParticleStore after = pk.particles;
  sortSpatially(after, pk.cell);
  ASSERT_EQ(after.size(), before.size());
  std::set<std::int32_t> ids;
  for (std::size_t k = 0; k < after.size(); ++k) {
    const std::size_t i = static_cast<std::size_t>(after.id[k]);  // gas ids are the original indices
    ids.insert(after.id[k]);
    EXPECT_EQ(after.pos[k], before.pos[i]);
    EXPECT_EQ(after.vel[k], before.vel[i]);
    EXPECT_EQ(after.angVel[k], before.angVel[i]);
    EXPECT_EQ(after.radius[k], before.radius[i]);
    EXPECT_EQ(after.invMass[k], before.invMass[i]);
    EXPECT_EQ(after.invInertia[k], before.invInertia[i]);
    EXPECT_EQ(after.material[k], before.material[i]);
  }
  EXPECT_EQ(ids.size(), before.size());
  // Morton codes are non-decreasing along the new order
  for (std::size_t k = 1; k < after.size(); ++k)
    EXPECT_LE(mortonCode(pk.cell.reduced(after.pos[k - 1])), mortonCode(pk.cell.reduced(after.pos[k])));

  // the same physical pairs, named by id
  const double skin = 0.3e-3;
  auto pairsById = [&](const ParticleStore& p, double* medianGap) {
    const PairList L = findPairsBruteForce(p, pk.cell, skin);
    std::set<std::pair<int, int>> s;
    std::vector<int> gaps;
    for (std::size_t k = 0; k < L.first.size(); ++k) {
      const int a = p.id[L.first[k]], b = p.id[L.second[k]];
      s.insert({std::min(a, b), std::max(a, b)});
      gaps.push_back(std::abs(L.second[k] - L.first[k]));
    }
    std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
    *medianGap = gaps[gaps.size() / 2];
    return s;
  };
  double gapBefore = 0.0, gapAfter = 0.0;
  const auto sb = pairsById(before, &gapBefore);
  const auto sa = pairsById(after, &gapAfter);
  EXPECT_GT(sb.size(), 300u);
  EXPECT_EQ(sa, sb);
  // locality: random order puts half the partners more than ~N/4 apart; along the Z-curve most partners
  // are a few dozen indices apart (the curve's jumps at octant boundaries are the exceptions)
  EXPECT_GT(gapBefore, 0.2 * double(before.size()));
  EXPECT_LT(gapAfter, 0.1 * gapBefore) << "median index gap " << gapBefore << " -> " << gapAfter;
}

TEST(SpatialOrder, RejectsAnOrderThatIsNotAPermutation) {
  Packing pk = gas(10, 0.2, 1);
  EXPECT_THROW(reorderParticles(pk.particles, {0, 1, 2}), InputError);
  std::vector<std::size_t> dup{0, 1, 2, 3, 4, 5, 6, 7, 8, 8};
  EXPECT_THROW(reorderParticles(pk.particles, dup), InputError);
  std::vector<std::size_t> out{0, 1, 2, 3, 4, 5, 6, 7, 8, 10};
  EXPECT_THROW(reorderParticles(pk.particles, out), InputError);
}

// The memory figure of the scaling benchmark (Simulation::memoryBytes) counts every particle and pair array:
// at least their element sizes, at most what vector growth can add (the arrays are sized, not grown).
TEST(SpatialOrder, MemoryBytesCountsParticleAndPairArrays) {
  Packing pk = gas(500, 0.3, 5);
  const std::size_t n = pk.particles.size();
  Simulation sim(std::move(pk.particles), pk.cell, {Material::paperGlass()}, NumericsSettings{});
  const std::size_t pairs = sim.contacts().size();
  ASSERT_GT(pairs, 0u);
  const std::size_t perParticle = 5 * sizeof(Vec3) + 3 * sizeof(double) + sizeof(std::int32_t) +
                                  sizeof(std::uint16_t) + sizeof(Vec3i) + sizeof(Vec3);  // + reference position
  const std::size_t perPair = 2 * sizeof(std::int32_t) + sizeof(Image) + sizeof(ContactHistory) +
                              sizeof(PairResult) + 2 * sizeof(std::int32_t);  // + adjacency
  const std::size_t lower = n * perParticle + pairs * perPair;
  EXPECT_GE(sim.memoryBytes(), lower);
  EXPECT_LE(sim.memoryBytes(), 2 * lower + 64 * 1024);
}
